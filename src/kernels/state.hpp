// Device state, one struct of views per entity (DESIGN.md 2). Units SI.
//
// Ordering invariants:
//  - Nodes: body by body (each body's nodes form one contiguous range), rows of the structured
//    mesh within a body. A node index never changes during a run.
//  - Elements: body by body, the mesh index never changes; `active` lists the indices of the
//    active (not converted) elements in increasing order.
//  - Quadrature points: element e owns points [e * qp_per_element, (e + 1) * qp_per_element).
#pragma once
#include "kernels/compat.hpp"
#include "kernels/materials.hpp"

namespace fracta {

enum FixedDof : int { kFixX = 1, kFixY = 2 };

struct Nodes {
  View<double* [2]> x0;     // reference position (m)
  View<double* [2]> x;      // current position (m)
  View<double* [2]> v;      // velocity (m/s); full step between steps, half step inside one
  View<double* [2]> f;      // internal + contact force (N), rebuilt every step
  View<double* [2]> f_ext;  // external force (N), rebuilt every step
  View<double*> mass;       // lumped mass (kg), constant
  View<int*> fixed;         // FixedDof bits
  View<int*> body;
  int count = 0;
};

struct Elements {
  View<int* [4]> nodes;  // counter-clockwise
  View<int*> material;   // index into the MaterialLaw table
  View<int*> body;
  View<int*> active;  // active element indices, increasing
  int count = 0;      // all elements of the mesh
  int active_count = 0;
  int qp_per_element = 1;  // 1 (reduced + hourglass control) or 4 (2x2 Gauss)
  // Per quadrature point.
  View<double* [4]> stress;      // Cauchy stress (Pa): xx, yy, zz, xy
  View<double*> epeq;            // equivalent plastic strain (paper Eq. 13)
  View<double*> qp_volume;       // current volume (m^3) the point represents
  View<double*> bulk_viscosity;  // last artificial viscous pressure q (Pa)
  // Per element.
  View<double* [2]> hourglass_disp;   // stiffness-form hourglass generalized displacement (m)
  View<double* [2]> hourglass_force;  // last generalized hourglass force (N)
  View<double*> strain_work;          // cumulative stress work (J): internal + plastic
  View<double*> plastic_work;         // cumulative (J)
  View<double*> hourglass_work;       // cumulative (J)
  View<double*> viscous_work;         // cumulative bulk-viscosity work (J)
};

// Piecewise-linear load tables, one per load, flattened: entries [offset[k], offset[k+1]).
struct LoadTables {
  View<double*> time;
  View<double*> value;
  View<int*> offset;
  int count = 0;
};

// Pressure acting on boundary edges: node a -> node b in the element's counter-clockwise order,
// so the outward normal times the edge length is (dy, -dx).
struct PressureEdges {
  View<int* [2]> nodes;
  View<int*> load;
  int count = 0;
};

// Concentrated forces on node sets: each entry carries a share of its load's total force.
struct NodalForces {
  View<int*> node;
  View<int*> load;
  View<double* [2]> force_per_unit;  // direction * share (N per unit table value)
  int count = 0;
};

KOKKOS_INLINE_FUNCTION double table_value(const LoadTables& t, int k, double time) {
  const int begin = t.offset(k), end = t.offset(k + 1);
  if (time <= t.time(begin)) return t.value(begin);
  for (int i = begin + 1; i < end; ++i) {
    if (time <= t.time(i)) {
      const double t0 = t.time(i - 1), t1 = t.time(i);
      // A repeated time is a jump: take the value after it once time passes it.
      if (t1 <= t0) return t.value(i);
      const double w = (time - t0) / (t1 - t0);
      return (1.0 - w) * t.value(i - 1) + w * t.value(i);
    }
  }
  return t.value(end - 1);
}

// Small fixed-size sum for parallel_reduce (works with Kokkos 3.4 and 4.x).
template <int N>
struct Sums {
  double v[N];
  KOKKOS_INLINE_FUNCTION Sums() {
    for (int i = 0; i < N; ++i) v[i] = 0.0;
  }
  KOKKOS_INLINE_FUNCTION Sums& operator+=(const Sums& o) {
    for (int i = 0; i < N; ++i) v[i] += o.v[i];
    return *this;
  }
  KOKKOS_INLINE_FUNCTION void operator+=(const volatile Sums& o) volatile {
    for (int i = 0; i < N; ++i) v[i] += o.v[i];
  }
};

}  // namespace fracta

namespace Kokkos {
template <int N>
struct reduction_identity<fracta::Sums<N>> {
  KOKKOS_FORCEINLINE_FUNCTION static fracta::Sums<N> sum() { return fracta::Sums<N>(); }
};
}  // namespace Kokkos

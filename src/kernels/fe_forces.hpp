// Finite-element internal forces (docs/physics.md 1.1): Q4 elements, updated Lagrangian.
// One kernel per step over the active elements, in named steps (FeForces::element): gather the
// corners -> kinematics (velocity gradient at mid-step, gradients at the current configuration)
// -> material update (Jaumann rotation of the stress, materials.hpp) -> bulk viscosity ->
// hourglass control -> nodal forces, added into the node accumulators (kernels/scatter.hpp). It
// also returns the element stable time step bound (stable_dt.hpp).
#pragma once
#include "kernels/compat.hpp"
#include "kernels/conversion.hpp"
#include "kernels/laws.hpp"
#include "kernels/materials.hpp"
#include "kernels/scatter.hpp"
#include "kernels/simd.hpp"
#include "kernels/stable_dt.hpp"
#include "kernels/state.hpp"

namespace fracta {

struct FeParams {
  double thickness = 1.0;  // m (plane strain: the modelled depth)
  // 1: axisymmetric (x = radius, y = axis; docs/physics.md 1.1, "Axisymmetry"): volumes 2 pi r dA,
  // the hoop strain rate v_r / r, the hoop stress's nodal forces; thickness unused. Quantities are
  // those of the full revolution.
  int axisymmetric = 0;
  double dt = 0.0;              // s, the step just taken (strain increment = D dt)
  int hourglass_stiffness = 0;  // 0 viscous, 1 stiffness form (Flanagan-Belytschko 1981)
  double hourglass_coefficient = 0.1;
  double bulk_linear = 0.06, bulk_quadratic = 1.5;
};

// Stress rotation for the Jaumann rate over a step, s' = Q s Q^T, with Q the Cayley transform
// (I - W dt/2)^-1 (I + W dt/2) of the spin (Hughes & Winget 1980): exactly orthogonal, and a
// rotation by 2 atan(w dt / 2) = w dt (1 - (w dt)^2 / 12 + ...), so second-order accurate.
// The first-order form s + (W s - s W) dt would not be orthogonal and would pump energy into a
// spinning stressed body at O((w dt)^2) per step; cos/sin of w dt would cost a libm call.
// cayley_rotation gives cos and sin of that rotation; rotate_stress applies it.
// T (here and below): double, or one element per lane (simd.hpp).
// Force-inlined: called twice per point on whole lanes, and a call would spill them (GCC
// outlines it once the element kernel grows).
template <class T>
KOKKOS_FORCEINLINE_FUNCTION void cayley_rotation(const T& w_dt, T& c, T& sn) {
  const T t = 0.5 * w_dt, inv = 1.0 / (1.0 + t * t);
  c = (1.0 - t * t) * inv;
  sn = 2.0 * t * inv;
}

template <class T>
KOKKOS_FORCEINLINE_FUNCTION void rotate_stress(T s[4], const T& c, const T& sn) {
  const T sxx = s[0], syy = s[1], sxy = s[3];
  s[0] = c * c * sxx + 2.0 * c * sn * sxy + sn * sn * syy;
  s[1] = sn * sn * sxx - 2.0 * c * sn * sxy + c * c * syy;
  s[3] = c * sn * (syy - sxx) + (c * c - sn * sn) * sxy;
}

KOKKOS_INLINE_FUNCTION void jaumann_rotate(double s[4], double w_dt) {
  double c, sn;
  cayley_rotation(w_dt, c, sn);
  rotate_stress(s, c, sn);
}

// Gradient operator of a Q4 at (xi, eta): dN/dx, dN/dy and det J.
template <class T>
KOKKOS_INLINE_FUNCTION T q4_gradients(const T x[4], const T y[4], double xi, double eta, T bx[4],
                                      T by[4]) {
  const double dn_dxi[4] = {-0.25 * (1 - eta), 0.25 * (1 - eta), 0.25 * (1 + eta),
                            -0.25 * (1 + eta)};
  const double dn_deta[4] = {-0.25 * (1 - xi), -0.25 * (1 + xi), 0.25 * (1 + xi), 0.25 * (1 - xi)};
  T j11 = splat<T>(0.0), j12 = j11, j21 = j11, j22 = j11;
  for (int a = 0; a < 4; ++a) {
    j11 += dn_dxi[a] * x[a];
    j12 += dn_dxi[a] * y[a];
    j21 += dn_deta[a] * x[a];
    j22 += dn_deta[a] * y[a];
  }
  const T det = j11 * j22 - j12 * j21;
  const T inv = det != 0.0 ? 1.0 / det : splat<T>(0.0);
  for (int a = 0; a < 4; ++a) {
    bx[a] = inv * (j22 * dn_dxi[a] - j12 * dn_deta[a]);
    by[a] = inv * (-j21 * dn_dxi[a] + j11 * dn_deta[a]);
  }
  return det;
}

// The natural coordinates (xi, eta) of 2x2 Gauss point g (counter-clockwise from (-, -)).
KOKKOS_INLINE_FUNCTION void gauss_point(int g, double& xi, double& eta) {
  const double gp = 0.57735026918962576;  // 1/sqrt(3)
  xi = (g == 0 || g == 3) ? -gp : gp;
  eta = (g < 2) ? -gp : gp;
}

// Gradients at quadrature point g; returns the point's weight (area, m^2).
// QP = 1: the uniform gradients b_a = (1/A) int dN_a/dx dA of Flanagan & Belytschko (1981,
// Eq. 14), exact element averages; QP = 4: 2x2 Gauss points.
template <int QP, class T>
KOKKOS_INLINE_FUNCTION T qp_gradients(const T x[4], const T y[4], int g, T bx[4], T by[4]) {
  if constexpr (QP == 1) {
    (void)g;
    const T A = 0.5 * ((x[2] - x[0]) * (y[3] - y[1]) + (x[1] - x[3]) * (y[2] - y[0]));
    const T inv2A = A != 0.0 ? 0.5 / A : splat<T>(0.0);
    for (int a = 0; a < 4; ++a) {
      bx[a] = inv2A * (y[(a + 1) % 4] - y[(a + 3) % 4]);
      by[a] = inv2A * (x[(a + 3) % 4] - x[(a + 1) % 4]);
    }
    return A;
  } else {
    double xi, eta;
    gauss_point(g, xi, eta);
    return q4_gradients(x, y, xi, eta, bx, by);
  }
}

// Shape function values N_a at quadrature point g (QP = 1: the centre; QP = 4: the 2x2 Gauss
// point of qp_gradients).
template <int QP>
KOKKOS_INLINE_FUNCTION void qp_shape_values(int g, double n[4]) {
  if constexpr (QP == 1) {
    (void)g;
    for (int a = 0; a < 4; ++a) n[a] = 0.25;
  } else {
    double xi, eta;
    gauss_point(g, xi, eta);
    const double xa[4] = {-1, 1, 1, -1}, ya[4] = {-1, -1, 1, 1};
    for (int a = 0; a < 4; ++a) n[a] = 0.25 * (1.0 + xa[a] * xi) * (1.0 + ya[a] * eta);
  }
}

// What an evaluation of the element forces returns besides the forces: the smallest element
// stable step (s, before the safety factor; negative if an element inverted) and the work
// dissipated over the step (J): plastic, hourglass, bulk viscosity. The dissipation is summed
// by the caller over the run; per element only the recoverable part is kept
// (Elements::recoverable_work), which the conversion hands to the bonds.
struct FeStepSums {
  double dt_min = 1e300;
  double plastic = 0.0, hourglass = 0.0, viscous = 0.0;
  double flagged = 0.0;  // elements flagged for conversion (so the host reads no counter if 0)
};

// Kokkos reducer of FeStepSums: min of dt, sums of the rest (a reducer, since Kokkos 3.4
// cannot combine a Min and a Sum in one parallel_reduce), into a host value (FeStepReducer) or a
// ResultSlot (FeStepReducerIn<MemSpace>).
template <class Space>
struct FeStepReducerIn {
  using reducer = FeStepReducerIn;
  using value_type = FeStepSums;
  using result_view_type = Kokkos::View<value_type, Space, Kokkos::MemoryUnmanaged>;
  result_view_type value;
  bool scalar = true;
  KOKKOS_INLINE_FUNCTION explicit FeStepReducerIn(value_type& v) : value(&v), scalar(true) {}
  KOKKOS_INLINE_FUNCTION explicit FeStepReducerIn(const result_view_type& v)
      : value(v), scalar(false) {}
  KOKKOS_INLINE_FUNCTION void join(value_type& dest, const value_type& src) const {
    dest.dt_min = dest.dt_min < src.dt_min ? dest.dt_min : src.dt_min;
    dest.plastic += src.plastic;
    dest.hourglass += src.hourglass;
    dest.viscous += src.viscous;
    dest.flagged += src.flagged;
  }
  KOKKOS_INLINE_FUNCTION void join(volatile value_type& dest,
                                   const volatile value_type& src) const {
    dest.dt_min = dest.dt_min < src.dt_min ? dest.dt_min : src.dt_min;
    dest.plastic += src.plastic;
    dest.hourglass += src.hourglass;
    dest.viscous += src.viscous;
    dest.flagged += src.flagged;
  }
  KOKKOS_INLINE_FUNCTION void init(value_type& v) const { v = FeStepSums(); }
  KOKKOS_INLINE_FUNCTION value_type& reference() const { return *value.data(); }
  result_view_type view() const { return value; }
  KOKKOS_INLINE_FUNCTION bool references_scalar() const { return scalar; }
};
using FeStepReducer = FeStepReducerIn<HostSpace>;

// QP = 1: one-point integration with the uniform-strain gradients of Flanagan & Belytschko
// (1981) (exact element averages), plus hourglass control. QP = 4: 2x2 Gauss, no hourglass.
//
// A work item is a batch of kLanes consecutive active elements (simd.hpp: 8 on CPUs, 1 on
// GPUs), run in groups of kNativeLanes (8 with AVX-512, else 4; simd.hpp, NativeDouble). When
// a group's elements share a material it runs as one element of type NativeDouble, each value
// holding the group's values; otherwise (and for the tail of the range) element by element as
// double. The element code is the same for both (element<T>). The material
// update is the one part that branches per element: every lane takes the elastic trial, and
// the lanes that may_leave_elastic marks (yielding, or near the conversion stresses) redo the
// whole update_stress one at a time, since return mappings iterate (hjc, whose pressure is not
// the elastic trial's: its own batched elastic step, hjc_batch_update).
// Axisymmetric: the formulation as a template parameter (FeParams::axisymmetric chooses it at
// the launch), so the plane kernels carry none of its terms.
// The gradient l = (L_xx, L_xy, L_yx, L_yy), L_ij = sum_a v_i,a dN_a/dx_j, of corner values
// (vx, vy) over a point's gradients (bx, by).
template <class T>
KOKKOS_INLINE_FUNCTION void gradient_of(const T (&vx)[4], const T (&vy)[4], const T (&bx)[4],
                                        const T (&by)[4], T (&l)[4]) {
  T lxx = splat<T>(0.0), lxy = lxx, lyx = lxx, lyy = lxx;
  for (int a = 0; a < 4; ++a) {
    lxx += vx[a] * bx[a];
    lxy += vx[a] * by[a];
    lyx += vy[a] * bx[a];
    lyy += vy[a] * by[a];
  }
  l[0] = lxx;
  l[1] = lxy;
  l[2] = lyx;
  l[3] = lyy;
}

template <int QP, bool Axisymmetric = false>
struct FeForces {
  Nodes nodes;
  Elements elements;
  View<const MaterialLaw*> materials;  // from material_law (cache_derived done)
  FeParams p;
  // Adaptive scenes: of the conversion criterion (ConversionCriterion), the elements that may
  // convert (per mesh element) and whether tension converts. The kernel counts in
  // conversion_pending the elements that may have met it after this update, so the conversion
  // pass runs only when there is something to convert.
  View<const int*> adaptive;
  bool on_tension = false;
  View<int> conversion_pending;      // number of flagged elements; empty: no check
  View<int*> conversion_candidates;  // active indices of the first flagged (any order)

  // Nodal forces: added straight into nodes.f (kernels/scatter.hpp), atomically when the
  // elements do not run by the chunks of a ScatterPlan (GPUs).
  bool atomic = true;
  // Rate-dependent tension cut-off (docs/physics.md 1.1, "Rate dependence"): per material, the
  // dynamic increase factors (a RateLaw with count 0: none) and the filtered node velocities the
  // strain rate is taken from; empty views: no material has one.
  View<const RateLaw*> tension_rates;
  View<double* [2]> v_filtered;

  static int batches(int active_count) { return (active_count + kLanes - 1) / kLanes; }

  // Atomic path: work item = one batch.
  KOKKOS_INLINE_FUNCTION void operator()(const int batch_index, FeStepSums& acc) const {
    batch(batch_index * kLanes, elements.active_count, acc);
  }

  // Chunk path: the active positions [begin, end) in batches, in order (begin is a multiple of
  // kLanes: scatter_chunk_size).
  KOKKOS_INLINE_FUNCTION void chunk(const int begin, const int end, FeStepSums& acc) const {
    for (int first = begin; first < end; first += kLanes) batch(first, end, acc);
  }

  // The batch of active positions [first, min(first + kLanes, end)), by groups of kNativeLanes.
  KOKKOS_INLINE_FUNCTION void batch(const int first, const int end, FeStepSums& acc) const {
    const int last = min_(first + kLanes, end);
    for (int group = first; group < last; group += kNativeLanes) {
      if constexpr (kNativeLanes > 1) {
        if (group + kNativeLanes <= last) {
          const int material = elements.material(elements.active(group));
          bool uniform = true;
          for (int l = 1; l < kNativeLanes; ++l)
            uniform = uniform && elements.material(elements.active(group + l)) == material;
          if (uniform) {
            element<NativeDouble>(group, acc);
            continue;
          }
        }
      }
      const int group_end = min_(group + kNativeLanes, last);
      for (int i = group; i < group_end; ++i) element<double>(i, acc);
    }
  }

  // The lanes of a batch: L = LaneCount<T> active elements of one material from active position
  // `first`, their mesh indices and corners. consecutive: e[l] = e[0] + l (active() increases),
  // so their per-element data moves as whole vectors. row: the batch lies along one row of a
  // structured mesh (structured_row: corner 0 of lane l at node n0 + l, corner 1 at n0 + l + 1,
  // corner 3 at m0 + l, corner 2 at m0 + l + 1, counter-clockwise), so its node data comes by
  // vector loads (load_pairs) instead of gathers, and its forces go by two vector adds per row of
  // nodes instead of 64 scalar ones.
  template <int L>
  struct ElementLanes {
    int first;
    int e[L], node[4][L];
    bool consecutive, row;
  };

  // What an element's step sums over its quadrature points, per lane.
  template <class T>
  struct ElementSums {
    using Mask = decltype(!all_lanes<T>());
    T plastic, viscous, strain_work, hourglass;  // work of the step (J)
    T area;                                      // sum of the points' weights (m^2)
    T div_rate;                                  // smallest velocity divergence, or 0 (1/s)
    T dt_element;                                // stable step bound (stable_dt.hpp)
    T wave_speed;  // P-wave speed of the stable step (m/s): the material's, or its points' now
    Mask inverted, convert;  // a point's weight not positive; flagged
  };

  // Active elements [first, first + L), L = LaneCount<T>, all of one material: gather the
  // corners, then per quadrature point the kinematics, the material update and the internal
  // forces (and the hourglass control of one-point elements), the stable step bound, and the
  // forces and sums scattered.
  template <class T>
  KOKKOS_INLINE_FUNCTION void element(const int first, FeStepSums& acc) const {
    constexpr int L = LaneCount<T>::value;
    const ElementLanes<L> lanes = element_lanes<L>(first);
    const MaterialLaw& mat = materials(elements.material(lanes.e[0]));
    T x[4], y[4], vx[4], vy[4], fx[4], fy[4];
    gather_corners(lanes, x, y, vx, vy);
    for (int a = 0; a < 4; ++a) fx[a] = fy[a] = splat<T>(0.0);
    const T zero = splat<T>(0.0);
    ElementSums<T> sum{zero,
                       zero,
                       zero,
                       zero,
                       zero,
                       zero,
                       splat<T>(1e300),
                       splat<T>(mat.p_wave_speed),
                       !all_lanes<T>(),
                       !all_lanes<T>()};
    // Axisymmetric: the hoop row of the gradient operator, N_a / r = 1 / (4 r_c) at the centre,
    // adds sum_a (N_a / r_c)^2 = 1 / (4 r_c^2) to sum b.b in the stable-step bound (stable_dt.hpp),
    // with r_c the mean radius of the corners (where the masses are lumped, model.cpp).
    T hoop_b2 = zero;
    if constexpr (Axisymmetric) {
      const T centre_radius = 0.25 * (x[0] + x[1] + x[2] + x[3]);
      hoop_b2 = 0.25 / (centre_radius * centre_radius);
    }
    for (int g = 0; g < QP; ++g) {
      T l[4], bx[4], by[4];
      velocity_gradient(x, y, vx, vy, g, l);
      const T weight = qp_gradients<QP>(x, y, g, bx, by);
      sum.inverted = sum.inverted || !(weight > 0.0);  // also catches NaN geometry
      sum.area += weight;
      // Axisymmetric: the point's radius and hoop strain rate; its volume of revolution.
      T radius = zero, hoop_rate = zero;
      T depth;
      if constexpr (Axisymmetric) {
        point_hoop(x, vx, g, radius, hoop_rate);
        depth = kTwoPi * radius;
      } else {
        depth = splat<T>(p.thickness);
      }
      const T volume = weight * depth;
      const T len = sqrt_(weight * QP);  // the bulk-viscosity length
      material_point(lanes, g, mat, l, hoop_rate, weight, volume, len, bx, by, fx, fy, sum);
      if constexpr (QP == 1) {
        T b2, sqrt_b2;
        hourglass(lanes, mat, x, y, vx, vy, bx, by, weight, depth, fx, fy, sum.hourglass, b2,
                  sqrt_b2);
        if constexpr (Axisymmetric) {
          b2 += hoop_b2;
          sqrt_b2 = sqrt_(b2);
        }
        // len is sqrt(weight) here (QP = 1).
        sum.dt_element = mat.model == kHjc
                             ? one_point_stable_dt(b2, sqrt_b2, len, sum.div_rate, sum.wave_speed,
                                                   p.bulk_linear, p.bulk_quadratic)
                             : one_point_stable_dt(b2, sqrt_b2, len, sum.div_rate, mat.p_wave_speed,
                                                   p.bulk_linear, p.bulk_quadratic);
      }
    }
    if constexpr (QP == 4)
      sum.dt_element =
          mat.model == kHjc
              ? full_integration_stable_dt(x, y, sqrt_(sum.area), sum.div_rate, sum.wave_speed,
                                           p.bulk_linear, p.bulk_quadratic, hoop_b2)
              : full_integration_stable_dt(x, y, sqrt_(sum.area), sum.div_rate, mat.p_wave_speed,
                                           p.bulk_linear, p.bulk_quadratic, hoop_b2);
    // Distortion (ConversionCriterion): the element's characteristic length against its
    // reference one, so that no adaptive element drives the step down by its shape.
    if (conversion_pending.data() != nullptr && mat.conversion_length_ratio > 0.0 &&
        elements.reference_gradient_norm2.extent(0) > 0) {
      const T reference =
          load_lanes<T>(elements.reference_gradient_norm2.data(), lanes.e, lanes.consecutive);
      sum.convert = sum.convert || length_ratio_below(x, y, reference, mat.conversion_length_ratio);
    }
    // Recoverable energy = stress work - plastic dissipation, both integrated per step (a state
    // function 1/2 s:C^-1:s V would drift against the nodal work as V changes).
    add_lanes(sum.strain_work - sum.plastic, elements.recoverable_work.data(), lanes.e,
              lanes.consecutive);
    scatter(lanes, fx, fy);
    reduce(lanes, sum, acc);
  }

  // ---- Gather ---------------------------------------------------------------------------------

  template <int L>
  KOKKOS_FORCEINLINE_FUNCTION ElementLanes<L> element_lanes(const int first) const {
    ElementLanes<L> lanes;
    lanes.first = first;
    for (int l = 0; l < L; ++l) {
      lanes.e[l] = elements.active(first + l);
      for (int a = 0; a < 4; ++a) lanes.node[a][l] = elements.nodes(lanes.e[l], a);
    }
    lanes.consecutive = lanes.e[L - 1] - lanes.e[0] == L - 1;
    lanes.row = L > 1 && nodes.x.stride_0() == 2 && nodes.v.stride_0() == 2 &&
                nodes.f.stride_0() == 2 && structured_row<L>(lanes.node);
    return lanes;
  }

  // Positions and velocities of the lanes' corners. Coordinate d of node n at &x(0, d) +
  // n * stride_0 (2 in LayoutRight, the CPU default).
  template <class T, int L>
  KOKKOS_FORCEINLINE_FUNCTION void gather_corners(const ElementLanes<L>& lanes, T (&x)[4],
                                                  T (&y)[4], T (&vx)[4], T (&vy)[4]) const {
    gather_corner_pairs(lanes, nodes.x, x, y);
    gather_corner_pairs(lanes, nodes.v, vx, vy);
  }

  // The lanes' corner values of a [n][2] node array (positions, velocities): component 0 in u,
  // 1 in w; by vector loads along a structured row of a LayoutRight array.
  template <class T, int L, class NodeView>
  KOKKOS_FORCEINLINE_FUNCTION void gather_corner_pairs(const ElementLanes<L>& lanes,
                                                       const NodeView& view, T (&u)[4],
                                                       T (&w)[4]) const {
    const int stride = static_cast<int>(view.stride_0());
    for (int a = 0; a < 4; ++a) {
#ifdef FRACTA_HOST_SIMD
      if constexpr (L > 1) {
        if (lanes.row && stride == 2) {
          load_pairs(&view(0, 0) + 2 * lanes.node[a][0], u[a], w[a]);
          continue;
        }
      }
#endif
      u[a] = gather_lanes<T>(&view(0, 0), lanes.node[a], stride);
      w[a] = gather_lanes<T>(&view(0, 1), lanes.node[a], stride);
    }
  }

  // ---- Kinematics -----------------------------------------------------------------------------

  // Velocity gradient l = (L_xx, L_xy, L_yx, L_yy), L_ij = dv_i/dx_j, at point g, measured at the
  // mid-step configuration x(n+1/2) = x(n+1) - dt/2 v(n+1/2) (second-order accurate, and what
  // keeps the energy balance free of drift); the forces are at the current configuration x(n+1).
  template <class T>
  KOKKOS_FORCEINLINE_FUNCTION void velocity_gradient(const T (&x)[4], const T (&y)[4],
                                                     const T (&vx)[4], const T (&vy)[4],
                                                     const int g, T (&l)[4]) const {
    T xm[4], ym[4], bx[4], by[4];
    for (int a = 0; a < 4; ++a) {
      xm[a] = x[a] - 0.5 * p.dt * vx[a];
      ym[a] = y[a] - 0.5 * p.dt * vy[a];
    }
    qp_gradients<QP>(xm, ym, g, bx, by);
    gradient_of(vx, vy, bx, by, l);
  }

  // Axisymmetric point g: its radius r = sum N_a x_a now (where the volume 2 pi r dA and the
  // forces are taken) and its hoop strain rate v_r / r, with r at mid-step like the velocity
  // gradient (0 at a point on the axis, where v_r = 0).
  template <class T>
  KOKKOS_FORCEINLINE_FUNCTION void point_hoop(const T (&x)[4], const T (&vx)[4], const int g,
                                              T& radius, T& hoop_rate) const {
    double n[4];
    qp_shape_values<QP>(g, n);
    T r = splat<T>(0.0), vr = r;
    for (int a = 0; a < 4; ++a) {
      r += n[a] * x[a];
      vr += n[a] * vx[a];
    }
    const T r_mid = r - 0.5 * p.dt * vr;
    radius = r;
    hoop_rate = r_mid > 0.0 ? vr / r_mid : splat<T>(0.0);
  }

  // ---- Material update ------------------------------------------------------------------------

  // Point g of the lanes: the stress update (update_point_stress), the conversion flag, the bulk
  // viscosity, the point's state written back, and its internal forces -volume s.b_a added to
  // fx, fy (axisymmetric: and the hoop stress's -2 pi dA N_a s_zz to fx; hoop_rate: the hoop
  // strain rate, 0 otherwise).
  template <class T, int L>
  KOKKOS_FORCEINLINE_FUNCTION void material_point(const ElementLanes<L>& lanes, const int g,
                                                  const MaterialLaw& mat, const T (&l)[4],
                                                  const T& hoop_rate, const T& weight,
                                                  const T& volume, const T& len, const T (&bx)[4],
                                                  const T (&by)[4], T (&fx)[4], T (&fy)[4],
                                                  ElementSums<T>& sum) const {
    int q[L];
    for (int k = 0; k < L; ++k) q[k] = lanes.e[k] * QP + g;
    const bool q_consecutive = lanes.consecutive && QP == 1;
    T s[4];
    for (int k = 0; k < 4; ++k) s[k] = load_lanes<T>(&elements.stress(0, k), q, q_consecutive);
    T epeq = load_lanes<T>(elements.epeq.data(), q, q_consecutive);
    const T volume_old = load_lanes<T>(elements.qp_volume.data(), q, q_consecutive);
    const T viscosity_old = load_lanes<T>(elements.bulk_viscosity.data(), q, q_consecutive);
    // The dynamic increase factor of the tension cut-off (1: none). hjc takes it only where its
    // step depends on it (hjc_batch_update): its conversion is by damage, so nothing reads an hjc
    // element's kept factor.
    T factor = splat<T>(1.0);
    PendingFactor<T, L> pending{nullptr, lanes, g, bx, by, volume, weight};
    if (tension_rates.extent(0) > 0) {
      const RateLaw& rate = tension_rates(elements.material(lanes.e[0]));
      if (rate.active()) {
        if (mat.model == kHjc)
          pending.rate = &rate;
        else
          factor = tension_factor_of(rate, lanes, g, bx, by, volume / weight, true);
      }
    }
    const auto full_update = update_point_stress(mat, l, hoop_rate, volume, volume_old, s, epeq,
                                                 sum, factor, pending, q);
    if (conversion_pending.data() != nullptr) {
      flag_conversion(mat, s, epeq, factor, sum.convert);
      if (mat.conversion_damage > 0.0)
        sum.convert =
            sum.convert || gather_lanes<T>(&elements.law_state(0, kLawDamage), q,
                                           static_cast<int>(elements.law_state.stride_0())) >=
                               mat.conversion_damage;
    }

    // Artificial bulk viscosity in compression (linear + quadratic, as LS-DYNA/Abaqus):
    // q = rho l (C2 l div^2 - C1 c div) for div < 0; it acts as a pressure on the forces only.
    T div = l[0] + l[3];
    if constexpr (Axisymmetric) div += hoop_rate;
    const T qv =
        div < 0.0 && weight > 0.0
            ? mat.density * len *
                  (p.bulk_quadratic * len * div * div - p.bulk_linear * mat.p_wave_speed * div)
            : splat<T>(0.0);
    // Trapezoidal work of the viscous pressure (see the hourglass work).
    sum.viscous += -0.5 * (viscosity_old + qv) * div * volume * p.dt;
    for (int k = 0; k < 4; ++k) store_lanes(s[k], &elements.stress(0, k), q, q_consecutive);
    // epeq changes only in the return mapping, and the viscous pressure of an element out of
    // compression stays 0: storing an unchanged value would only write its cache line back
    // (8 B per element-step each; most elements are elastic, half are out of compression).
    if (any_lane(full_update)) store_lanes(epeq, elements.epeq.data(), q, q_consecutive);
    store_lanes(volume, elements.qp_volume.data(), q, q_consecutive);
    if (any_lane(qv != viscosity_old))
      store_lanes(qv, elements.bulk_viscosity.data(), q, q_consecutive);
    sum.div_rate = sum.div_rate < div ? sum.div_rate : div;
    const T sxx = s[0] - qv, syy = s[1] - qv, sxy = s[3];
    for (int a = 0; a < 4; ++a) {
      fx[a] -= volume * (sxx * bx[a] + sxy * by[a]);
      fy[a] -= volume * (sxy * bx[a] + syy * by[a]);
    }
    if constexpr (Axisymmetric) {
      // f_r,a = -int (s_rr dN_a/dr + s_rz dN_a/dz + s_tt N_a / r) 2 pi r dA: the last term is
      // the hoop stress's, -2 pi dA N_a s_tt (the Galerkin weak form weighted by r).
      double n[4];
      qp_shape_values<QP>(g, n);
      const T hoop_force = kTwoPi * weight * (s[2] - qv);
      for (int a = 0; a < 4; ++a) fx[a] -= n[a] * hoop_force;
    }
  }

  // The inputs of tension_factor_of at a point, for a factor taken only where a step needs it
  // (hjc_batch_update); rate nullptr: none pending.
  template <class T, int L>
  struct PendingFactor {
    const RateLaw* rate;
    const ElementLanes<L>& lanes;
    int g;
    const T (&bx)[4];
    const T (&by)[4];
    const T& volume;
    const T& weight;  // depth = volume / weight, divided only when the factor is taken
  };

  // The stress s (xx, yy, zz, xy) and epeq of a point after the step of velocity gradient l
  // (materials.hpp), its plastic and stress work added to the sums; returns the lanes that took
  // the full update. The strain increment is measured at the mid-step configuration, so it is
  // added in the mid-step frame: rotate by half the step's spin, update, rotate by the other half
  // (the Jaumann rate). Rotating by the whole spin first would add each increment in a frame
  // turned by half a step, a circulatory coupling of the deviatoric modes that makes a spinning
  // body unstable (energy growth ~ exp(omega * c dt / h * t), after ~60 rad at dt_safety 0.85).
  // Every lane takes the elastic trial, and the lanes that may_leave_elastic marks (yielding, or
  // near the conversion stresses) redo the whole update_stress one at a time, since return
  // mappings iterate.
  // q: the lanes' point indices, for the state of laws that have one (Elements::law_state).
  // factor: the lanes' tension factor; set here where pending (hjc) and the step needs it.
  template <class T, int L>
  KOKKOS_FORCEINLINE_FUNCTION auto update_point_stress(const MaterialLaw& mat, const T (&l)[4],
                                                       const T& hoop_rate, const T& volume,
                                                       const T& volume_old, T (&s)[4], T& epeq,
                                                       ElementSums<T>& sum, T& factor,
                                                       const PendingFactor<T, L>& pending,
                                                       const int (&q)[L]) const {
    static_assert(L == LaneCount<T>::value, "one point index per lane");
    T rot_c, rot_s;  // the half-step rotation, used twice
    cayley_rotation<T>(0.25 * (l[1] - l[2]) * p.dt, rot_c, rot_s);
    rotate_stress(s, rot_c, rot_s);
    const T deps[3] = {l[0] * p.dt, l[3] * p.dt, 0.5 * (l[1] + l[2]) * p.dt};
    const T deps_zz = hoop_rate * p.dt;  // axisymmetric: the hoop increment; else 0
    const T s_old[4] = {s[0], s[1], s[2], s[3]};
    using Mask = decltype(!all_lanes<T>());
    Mask full_update;
    if (mat.model == kHjc) {
      full_update = hjc_batch_update(mat, deps, deps_zz, s, sum.wave_speed, factor, pending, q);
    } else {
      if constexpr (Axisymmetric)
        elastic_increment_3d(mat, deps, deps_zz, s);
      else
        elastic_increment(mat, deps, s);
      full_update = may_leave_elastic(mat, s, epeq);
    }
    if (any_lane(full_update)) {
      T plastic = sum.plastic;  // a local for the lane writes, so `sum` stays in registers
      for (int k = 0; k < L; ++k) {
        if (!get_lane(full_update, k)) continue;
        double sl[4] = {get_lane(s_old[0], k), get_lane(s_old[1], k), get_lane(s_old[2], k),
                        get_lane(s_old[3], k)};
        const double dl[3] = {get_lane(deps[0], k), get_lane(deps[1], k), get_lane(deps[2], k)};
        const double dzz = get_lane(deps_zz, k), hoop = get_lane(hoop_rate, k);
        double ep = get_lane(epeq, k);
        // A raised cut-off only widens the elastic range, so the static law's may_leave_elastic
        // above still marks every lane that may leave it.
        const double f = get_lane(factor, k);
        double work = 0.0;
        if (has_law_state(mat.model)) {
          work = f != 1.0 ? law_point_update(detail::with_tension_factor(mat, f), l, hoop, k, q[k],
                                             dl, sl, ep, sum.wave_speed)
                          : law_point_update(mat, l, hoop, k, q[k], dl, sl, ep, sum.wave_speed);
        } else {
          work = f != 1.0
                     ? fracta::update_stress(detail::with_tension_factor(mat, f), dl, sl, ep, dzz)
                     : fracta::update_stress(mat, dl, sl, ep, dzz);
        }
        work *= get_lane(volume, k);
        set_lane(plastic, k, get_lane(plastic, k) + work);
        set_lane(epeq, k, ep);
        for (int c = 0; c < 4; ++c) set_lane(s[c], k, sl[c]);
      }
      sum.plastic = plastic;
    }
    // Stress work by the trapezoidal rule (as the nodal work of central differences):
    // dW = (s(n) + s(n+1))/2 : deps * V(n+1/2). In plane strain deps_zz = 0; in plane
    // stress s_zz = 0, so the in-plane terms are the whole product; axisymmetric adds the hoop
    // term.
    T power = (s_old[0] + s[0]) * deps[0] + (s_old[1] + s[1]) * deps[1] +
              2.0 * (s_old[3] + s[3]) * deps[2];
    if constexpr (Axisymmetric) power += (s_old[2] + s[2]) * deps_zz;
    sum.strain_work += 0.5 * power * 0.5 * (volume_old + volume);
    rotate_stress(s, rot_c, rot_s);
    return full_update;
  }

  // The hjc lanes' elastic step at once (hjc_elastic_update): the stress s, the state of the
  // points q and the lanes' wave speeds of the lanes it takes, with the tension limit raised by
  // factor; returns the others, for hjc_update one at a time. Most of a
  // concrete target is elastic in most steps, and the one-at-a-time update's power, logarithm and
  // lane traffic cost three times the rest of the element (docs/performance.md).
  // With a factor pending (a rate table), the step is first taken with the factor 1: where every
  // lane's step is then the same for any factor (factor_free; the table's factors are at least 1,
  // case.cpp), as in most steps of most points, the factor is not needed. Otherwise it is taken
  // (tension_factor_of) and the step redone with it.
  template <class T, int L>
  KOKKOS_FORCEINLINE_FUNCTION auto hjc_batch_update(const MaterialLaw& mat, const T (&deps)[3],
                                                    const T& deps_zz, T (&s)[4], T& wave_speed,
                                                    T& factor, const PendingFactor<T, L>& pending,
                                                    const int (&q)[L]) const {
    static_assert(kLawStateSize == 3, "the state moves as triples");
    // Elements::law_state is LayoutRight ([n][3], rows of 3) wherever the element kernel runs in
    // SIMD lanes (host); on GPUs (one lane) any layout.
    T state[kLawStateSize];
    const bool rows_of_three = elements.law_state.stride_0() == 3;
    if (rows_of_three) {
      load_triple_lanes(elements.law_state.data(), q, state);
    } else {
      const int stride = static_cast<int>(elements.law_state.stride_0());
      for (int c = 0; c < kLawStateSize; ++c)
        state[c] = gather_lanes<T>(&elements.law_state(0, c), q, stride);
    }
    T s_new[4], mu, mu_max, point_wave_speed;
    auto factor_free = !all_lanes<T>();
    auto taken = hjc_elastic_update(mat, deps, deps_zz, s, state, factor, s_new, mu, mu_max,
                                    point_wave_speed, factor_free);
    if (pending.rate != nullptr && any_lane(!factor_free)) {
      factor = tension_factor_of(*pending.rate, pending.lanes, pending.g, pending.bx, pending.by,
                                 pending.volume / pending.weight, false);
      taken = hjc_elastic_update(mat, deps, deps_zz, s, state, factor, s_new, mu, mu_max,
                                 point_wave_speed, factor_free);
    }
    if (!any_lane(taken)) return !taken;
    for (int c = 0; c < 4; ++c) s[c] = taken ? s_new[c] : s[c];
    wave_speed = taken ? max_(wave_speed, point_wave_speed) : wave_speed;
    // The damage does not change in an elastic step; the lanes not taken keep their state for
    // hjc_update.
    state[kHjcMu] = taken ? mu : state[kHjcMu];
    state[kHjcMuMax] = taken ? mu_max : state[kHjcMuMax];
    if (rows_of_three) {
      store_triple_lanes(elements.law_state.data(), q, state);
    } else {
      for (int k = 0; k < L; ++k) {
        if (!get_lane(taken, k)) continue;
        elements.law_state(q[k], kHjcMu) = get_lane(mu, k);
        elements.law_state(q[k], kHjcMuMax) = get_lane(mu_max, k);
      }
    }
    return !taken;
  }

  // Lane k of a law with a state (update_stress_with_state: hjc, johnson_cook) at point q: its
  // state read and written back, its equivalent strain rate sqrt(2/3 d':d') from the velocity
  // gradient l (and the hoop rate, axisymmetric), and the lane's wave speed raised to the
  // point's (law_wave_speed) for the stable step. Returns the dissipation density (J/m^3).
  template <class T>
  KOKKOS_FORCEINLINE_FUNCTION double law_point_update(const MaterialLaw& mat, const T (&l)[4],
                                                      const double hoop_rate, const int k,
                                                      const int q, const double (&deps)[3],
                                                      double (&s)[4], double& epeq,
                                                      T& wave_speed) const {
    const double lxx = get_lane(l[0], k), lyy = get_lane(l[3], k);
    const double dxy = 0.5 * (get_lane(l[1], k) + get_lane(l[2], k));
    // d_zz: 0 in plane strain; in plane stress that of isochoric (plastic) flow, -(d_xx + d_yy),
    // the flow whose rate the laws' rate terms act on; axisymmetric: the hoop rate.
    const double dzz = Axisymmetric ? hoop_rate : mat.plane_strain ? 0.0 : -(lxx + lyy);
    const double mean = (lxx + lyy + dzz) / 3.0;
    const double d0 = lxx - mean, d1 = lyy - mean, d2 = dzz - mean;
    const double rate = sqrt_(2.0 / 3.0 * (d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * dxy * dxy));
    double state[kLawStateSize];
    for (int c = 0; c < kLawStateSize; ++c) state[c] = elements.law_state(q, c);
    const double work =
        update_stress_with_state(mat, deps, s, epeq, state, rate, Axisymmetric ? dzz * p.dt : 0.0);
    for (int c = 0; c < kLawStateSize; ++c) elements.law_state(q, c) = state[c];
    set_lane(wave_speed, k, max_(get_lane(wave_speed, k), law_wave_speed(mat, state)));
    return work;
  }

  // ConversionCriterion on the values in hand, without its square root: the largest principal
  // stress c + r reaches T' when T' - c <= 0 or r^2 >= (T' - c)^2. Generous (r within 5e-7 of
  // T' - c, or c within 1e-9 T' of T'), far beyond the round-off of either form, so every
  // element the exact criterion takes is flagged: the conversion re-checks only the flagged ones
  // exactly, and a false alarm costs one check. T' is the tensile strength times the lanes'
  // tension_factor (the rate-dependent cut-off's, tension_factor_of; 1 without one).
  template <class T, class Mask>
  KOKKOS_FORCEINLINE_FUNCTION void flag_conversion(const MaterialLaw& mat, const T (&s)[4],
                                                   const T& epeq, const T& tension_factor,
                                                   Mask& convert) const {
    if (mat.conversion_strain > 0.0) convert = convert || epeq >= mat.conversion_strain;
    // hjc fails in tension through its damage (conversion_damage), at its hydrostatic limit.
    if (on_tension && mat.tensile_strength > 0.0 && mat.model != kHjc) {
      const T centre = 0.5 * (s[0] + s[1]);
      const T r2 = 0.25 * (s[0] - s[1]) * (s[0] - s[1]) + s[3] * s[3];
      const T limit = mat.tensile_strength * (1.0 - 1e-9) * tension_factor;
      const T d = limit - centre;
      convert = convert || d <= 1e-9 * limit || r2 >= d * d * (1.0 - 1e-6);
    }
  }

  // The dynamic increase factor of the lanes' tension cut-off at point g (tension_rates): the
  // table's strength factor at the largest principal strain rate (1/s, 0 in compression; in
  // plane, and axisymmetric also the hoop rate v_r / r at the point's radius, depth / 2 pi) of
  // the filtered velocities (filter_velocities, bond_forces.hpp) over the point's gradients bx,
  // by. With keep, each element keeps the smallest over its points in tension_factor, which the
  // conversion criterion reads, so a point held at its raised cut-off converts.
  template <class T, int L>
  KOKKOS_FORCEINLINE_FUNCTION T tension_factor_of(const RateLaw& rate, const ElementLanes<L>& lanes,
                                                  const int g, const T (&bx)[4], const T (&by)[4],
                                                  const T& depth, const bool keep) const {
    // The filtered velocities of the corners, and their gradient.
    T vx[4], vy[4], l[4];
    gather_corner_pairs(lanes, v_filtered, vx, vy);
    gradient_of(vx, vy, bx, by, l);
    const T lxx = l[0], lxy = l[1], lyx = l[2], lyy = l[3];
    const T dxy = 0.5 * (lxy + lyx);
    T largest = 0.5 * (lxx + lyy) + sqrt_(0.25 * (lxx - lyy) * (lxx - lyy) + dxy * dxy);
    if constexpr (Axisymmetric) {
      double n[4];
      qp_shape_values<QP>(g, n);
      T vr = splat<T>(0.0);
      for (int a = 0; a < 4; ++a) vr += n[a] * vx[a];
      const T radius = depth / kTwoPi;
      largest = radius > 0.0 ? max_(largest, vr / radius) : largest;
    }
    const T rate_now = max_(largest, splat<T>(0.0));
    const T factor = rate.strength_factor(rate_now);
    if (!keep) return factor;
    const T kept =
        g == 0 ? factor
               : min_(load_lanes<T>(elements.tension_factor.data(), lanes.e, lanes.consecutive),
                      factor);
    store_lanes(kept, elements.tension_factor.data(), lanes.e, lanes.consecutive);
    return factor;
  }

  // ---- Hourglass control ----------------------------------------------------------------------

  // Flanagan-Belytschko hourglass control of a one-point element: gamma_a = 1/4 (h_a - (h.x_i)
  // b_ia) is orthogonal to every linear field, so it resists only the hourglass mode. Adds the
  // generalized hourglass force's nodal forces to fx, fy and its work to `work`; b2 = sum b.b and
  // sqrt_b2 its root (for the stable step).
  template <class T, int L>
  KOKKOS_FORCEINLINE_FUNCTION void hourglass(const ElementLanes<L>& lanes, const MaterialLaw& mat,
                                             const T (&x)[4], const T (&y)[4], const T (&vx)[4],
                                             const T (&vy)[4], const T (&bx)[4], const T (&by)[4],
                                             const T& weight, const T& depth, T (&fx)[4],
                                             T (&fy)[4], T& work, T& b2, T& sqrt_b2) const {
    const double h[4] = {1.0, -1.0, 1.0, -1.0};
    T hx = splat<T>(0.0), hy = hx;
    for (int a = 0; a < 4; ++a) {
      hx += h[a] * x[a];
      hy += h[a] * y[a];
    }
    T gamma[4];
    T qdot_x = splat<T>(0.0), qdot_y = qdot_x;
    for (int a = 0; a < 4; ++a) {
      gamma[a] = 0.25 * (h[a] - hx * bx[a] - hy * by[a]);
      qdot_x += vx[a] * gamma[a];
      qdot_y += vy[a] * gamma[a];
    }
    b2 = splat<T>(0.0);
    for (int a = 0; a < 4; ++a) b2 += bx[a] * bx[a] + by[a] * by[a];
    sqrt_b2 = sqrt_(b2);
    T gx, gy;  // generalized hourglass force
    if (p.hourglass_stiffness) {
      // k = kappa (P-wave modulus) t A sum(b.b): an element-size-independent stiffness. t: the
      // depth (axisymmetric: 2 pi r_c, the volume-weighted form; docs/physics.md 1.1,
      // "Axisymmetry").
      const T k = p.hourglass_coefficient * mat.p_wave_modulus() * depth * weight * b2;
      double* qx_column = &elements.hourglass_disp(0, 0);
      double* qy_column = &elements.hourglass_disp(0, 1);
      const T qx = load_lanes<T>(qx_column, lanes.e, lanes.consecutive) + qdot_x * p.dt;
      const T qy = load_lanes<T>(qy_column, lanes.e, lanes.consecutive) + qdot_y * p.dt;
      store_lanes(qx, qx_column, lanes.e, lanes.consecutive);
      store_lanes(qy, qy_column, lanes.e, lanes.consecutive);
      gx = k * qx;
      gy = k * qy;
    } else {
      // Viscous: damping coefficient kappa rho c t A sqrt(sum b.b) (kg/s).
      const T cv =
          p.hourglass_coefficient * mat.density * mat.p_wave_speed * depth * weight * sqrt_b2;
      gx = cv * qdot_x;
      gy = cv * qdot_y;
    }
    // Work of the hourglass forces by the trapezoidal rule dW = (g(n) + g(n+1))/2 . dq, the rule
    // under which central differences conserve energy exactly up to a bounded O(dt^2) term
    // (exact for the stiffness form's stored energy k q^2 / 2).
    double* gx_column = &elements.hourglass_force(0, 0);
    double* gy_column = &elements.hourglass_force(0, 1);
    const T gx_old = load_lanes<T>(gx_column, lanes.e, lanes.consecutive);
    const T gy_old = load_lanes<T>(gy_column, lanes.e, lanes.consecutive);
    work += 0.5 * ((gx_old + gx) * qdot_x + (gy_old + gy) * qdot_y) * p.dt;
    store_lanes(gx, gx_column, lanes.e, lanes.consecutive);
    store_lanes(gy, gy_column, lanes.e, lanes.consecutive);
    for (int a = 0; a < 4; ++a) {
      fx[a] -= gx * gamma[a];
      fy[a] -= gy * gamma[a];
    }
  }

  // ---- Scatter --------------------------------------------------------------------------------

  // The lanes' corner forces added into nodes.f. Along a row (CPU chunk path): node n0 + l takes
  // corner 0 of lane l and corner 1 of lane l - 1, and n0 + L corner 1 of lane L - 1 (likewise m0
  // with corners 3 and 2). Otherwise element by element in lane order, so a node shared by two
  // lanes sums them in element order.
  template <class T, int L>
  KOKKOS_FORCEINLINE_FUNCTION void scatter(const ElementLanes<L>& lanes, const T (&fx)[4],
                                           const T (&fy)[4]) const {
#ifdef FRACTA_HOST_SIMD
    if constexpr (L > 1) {
      if (lanes.row && !atomic) {
        double* f = nodes.f.data();
        const int rows[2][3] = {{lanes.node[0][0], 0, 1}, {lanes.node[3][0], 3, 2}};
        for (const auto& r : rows) {
          const int n0 = r[0], a = r[1], b = r[2];
          add_pairs(f + 2 * n0, fx[a] + shift_up_one_lane(fx[b]), fy[a] + shift_up_one_lane(fy[b]));
          f[2 * (n0 + L)] += fx[b][L - 1];
          f[2 * (n0 + L) + 1] += fy[b][L - 1];
        }
        return;
      }
    }
#endif
    for (int l = 0; l < L; ++l)
      for (int a = 0; a < 4; ++a) {
        scatter_add(&nodes.f(lanes.node[a][l], 0), get_lane(fx[a], l), atomic);
        scatter_add(&nodes.f(lanes.node[a][l], 1), get_lane(fy[a], l), atomic);
      }
  }

  // The lanes' sums into the reduction, and the flagged elements of the adaptive set counted
  // (the first conversion_candidates.extent(0) keep their active index).
  template <class T, int L>
  KOKKOS_FORCEINLINE_FUNCTION void reduce(const ElementLanes<L>& lanes, const ElementSums<T>& sum,
                                          FeStepSums& acc) const {
    for (int l = 0; l < L; ++l) {
      const double dt_e = get_lane(sum.dt_element, l);
      acc.dt_min = acc.dt_min < dt_e ? acc.dt_min : dt_e;
      if (get_lane(sum.inverted, l)) acc.dt_min = -1.0;  // signals an inverted element to the host
      acc.plastic += get_lane(sum.plastic, l);
      acc.hourglass += get_lane(sum.hourglass, l);
      acc.viscous += get_lane(sum.viscous, l);
      if (get_lane(sum.convert, l) && adaptive(lanes.e[l])) {
        acc.flagged += 1.0;
        const int slot = Kokkos::atomic_fetch_add(&conversion_pending(), 1);
        if (slot >= 0 && slot < static_cast<int>(conversion_candidates.extent(0)))
          conversion_candidates(slot) = lanes.first + l;
      }
    }
  }
};

// Launches the element kernel, which adds the element forces to nodes.f; returns the smallest
// element stable step and the step's dissipation (FeStepSums). With conversion_pending given,
// the kernel also counts in it the elements (of criterion's adaptive set) that may have reached
// their conversion criterion (a superset of those that have), and writes the active indices of
// the first ones into conversion_candidates (as many as it holds; compact_candidates in
// conversion.hpp). Without a usable elements.scatter (the plan of the active list:
// update_scatter_plan) the forces are added atomically. With a slot given, the sums go there
// (ResultSlot: the launch does not wait) and the value returned is empty.
template <class Kernel>
inline FeStepSums launch_fe_forces(const char* name, Kernel kernel,
                                   const ResultSlot<FeStepSums>& into) {
  const int active_count = kernel.elements.active_count;
  FeStepSums sums;
  if (kernel.elements.scatter.usable(active_count)) {
    kernel.atomic = false;
    const ScatterPlan plan = kernel.elements.scatter;
    sums = for_each_chunk<FeStepReducer>(name, plan, std::move(kernel));
    if (!into.data()) return sums;
    put(into, sums);
    return FeStepSums();
  }
  const auto policy = Kokkos::RangePolicy<ExecSpace>(0, Kernel::batches(active_count));
  if (into.data())
    Kokkos::parallel_reduce(slot_label(name), policy, kernel, FeStepReducerIn<MemSpace>(into));
  else
    Kokkos::parallel_reduce(name, policy, kernel, FeStepReducer(sums));
  return sums;
}

// The views the element kernel uses (node_motion_views and these): each view a kernel's functor
// holds costs an atomic per host copy (for_each_chunk, scatter.hpp), and an adaptive body's disc
// and cell views, which the element kernel never reads, would make its launch dearer than pure
// FE's.
inline Elements fe_element_views(const Elements& elements) {
  Elements k;
  k.nodes = elements.nodes;
  k.material = elements.material;
  k.active = elements.active;
  k.count = elements.count;
  k.active_count = elements.active_count;
  k.qp_per_element = elements.qp_per_element;
  k.stress = elements.stress;
  k.epeq = elements.epeq;
  k.qp_volume = elements.qp_volume;
  k.bulk_viscosity = elements.bulk_viscosity;
  k.hourglass_disp = elements.hourglass_disp;
  k.hourglass_force = elements.hourglass_force;
  k.recoverable_work = elements.recoverable_work;
  k.reference_gradient_norm2 = elements.reference_gradient_norm2;
  k.tension_factor = elements.tension_factor;
  k.law_state = elements.law_state;
  k.scatter = elements.scatter;
  return k;
}

// tension_rates (per material) and the nodes' v_filtered: the rate-dependent tension cut-off,
// when a material has one (empty: none). into: a slot for the sums (the value returned is then
// empty), or none.
inline FeStepSums compute_fe_forces(const Nodes& nodes, const Elements& elements,
                                    const View<const MaterialLaw*>& materials, const FeParams& p,
                                    const ConversionCriterion& criterion = {},
                                    const View<int>& conversion_pending = {},
                                    const View<int*>& conversion_candidates = {},
                                    const View<const RateLaw*>& tension_rates = {},
                                    const ResultSlot<FeStepSums>& into = {}) {
  if (elements.active_count == 0) {
    if (into.data()) put(into, FeStepSums());
    return FeStepSums();
  }
  const View<double* [2]> v_filtered =
      tension_rates.extent(0) > 0 ? nodes.v_filtered : View<double* [2]>();
  const auto launch = [&](const char* name, auto kernel) {
    kernel.nodes = node_motion_views(nodes);
    kernel.elements = fe_element_views(elements);
    kernel.materials = materials;
    kernel.p = p;
    kernel.adaptive = criterion.adaptive;
    kernel.on_tension = criterion.on_tension;
    kernel.conversion_pending = conversion_pending;
    kernel.conversion_candidates = conversion_candidates;
    kernel.tension_rates = tension_rates;
    kernel.v_filtered = v_filtered;
    return launch_fe_forces(name, kernel, into);
  };
  if (p.axisymmetric)
    return elements.qp_per_element == 1
               ? launch("fracta::fe_forces_axisymmetric", FeForces<1, true>{})
               : launch("fracta::fe_forces_full_axisymmetric", FeForces<4, true>{});
  return elements.qp_per_element == 1 ? launch("fracta::fe_forces", FeForces<1>{})
                                      : launch("fracta::fe_forces_full", FeForces<4>{});
}

}  // namespace fracta

// The bonded disc lattice (DESIGN.md 1.2): elasticity of the lattice against the continuum,
// rigid motions, angular momentum, and the bond failure calibration.
#include <gtest/gtest.h>

#include <cmath>

#include "host/simulation.hpp"
#include "kernels/bond_forces.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

Case lattice_case(int nx, int ny, double h, double E, double nu, Formulation f) {
  Case c = test::rectangle_case(nx, ny, h, E, nu, 7800.0, f);
  c.bodies[0].method = BodyMethod::de;
  c.sim.end_time = 1.0;
  return c;
}

// Imposes the homogeneous strain eps (symmetric, so the discs do not rotate) on the lattice in
// one step and returns the stress the boundary forces carry: sxx from the right edge, syy from
// the top edge, sxy from the right edge's y forces. Also returns the largest interior force.
struct LatticeResponse {
  double sxx, syy, sxy, interior_force;
};

LatticeResponse impose_strain(const Case& c, const double eps[2][2]) {
  Case fixed_dt = c;
  Simulation probe(c);
  fixed_dt.sim.dt = 0.5 * probe.stable_dt_bound();
  Simulation sim(fixed_dt);
  Nodes& n = sim.model().nodes;
  const double dt = sim.dt();
  auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), n.x0);
  auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), n.v);
  for (int i = 0; i < n.count; ++i)
    for (int d = 0; d < 2; ++d) v(i, d) = (eps[d][0] * x0(i, 0) + eps[d][1] * x0(i, 1)) / dt;
  Kokkos::deep_copy(n.v, v);
  sim.step();  // x = (I + eps) x0; the bond forces are those of the strained lattice
  auto f = Kokkos::create_mirror_view_and_copy(HostSpace(), n.f);
  const double W = c.bodies[0].shape.width, H = c.bodies[0].shape.height, t = c.sim.thickness;
  const double tol = 1e-3 * c.bodies[0].cell_size;
  LatticeResponse r{0, 0, 0, 0};
  double fx_right = 0, fy_right = 0, fy_top = 0;
  for (int i = 0; i < n.count; ++i) {
    const bool right = x0(i, 0) > W - tol, top = x0(i, 1) > H - tol;
    const bool left = x0(i, 0) < tol, bottom = x0(i, 1) < tol;
    if (right) {
      fx_right += f(i, 0);
      fy_right += f(i, 1);
    }
    if (top) fy_top += f(i, 1);
    if (!right && !top && !left && !bottom)
      r.interior_force = std::max({r.interior_force, std::fabs(f(i, 0)), std::fabs(f(i, 1))});
  }
  // The bonds pull the edge inwards; the traction that holds the strain is the opposite.
  r.sxx = -fx_right / (H * t);
  r.syy = -fy_top / (W * t);
  r.sxy = -fy_right / (H * t);
  return r;
}

// Elastic constants of the lattice from imposed uniaxial strain and pure shear: E and nu of
// uniaxial stress follow from C11, C12 (plane stress: nu = C12/C11, E = C11 (1 - nu^2); plane
// strain: nu = C12/(C11 + C12), E = C11 (1 + nu)(1 - 2 nu)/(1 - nu)) and G = sxy / (2 eps_xy).
// The strain is 1e-6, so the lattice's geometric nonlinearity is O(1e-6); the tolerance 1e-4
// is that with margin (the issue asks for 1%).
void check_lattice(double E, double nu, Formulation f) {
  const Case c = lattice_case(12, 8, 1e-3, E, nu, f);
  const double e = 1e-6;
  const double uniaxial[2][2] = {{e, 0}, {0, 0}};
  const double shear[2][2] = {{0, e}, {e, 0}};
  const LatticeResponse a = impose_strain(c, uniaxial);
  const LatticeResponse s = impose_strain(c, shear);
  const double C11 = a.sxx / e, C12 = a.syy / e;
  double nu_m, E_m;
  if (f == Formulation::plane_stress) {
    nu_m = C12 / C11;
    E_m = C11 * (1 - nu_m * nu_m);
  } else {
    nu_m = C12 / (C11 + C12);
    E_m = C11 * (1 + nu_m) * (1 - 2 * nu_m) / (1 - nu_m);
  }
  const double G_m = s.sxy / (2 * e);
  EXPECT_NEAR(E_m, E, 1e-4 * E) << to_string(f) << " nu " << nu;
  EXPECT_NEAR(nu_m, nu, 1e-4 * nu) << to_string(f) << " nu " << nu;
  EXPECT_NEAR(G_m, E / (2 * (1 + nu)), 1e-4 * E) << to_string(f) << " nu " << nu;
  // Homogeneous strain is an equilibrium state of the lattice: no force on interior discs.
  EXPECT_LT(a.interior_force, 1e-6 * std::fabs(a.sxx) * 1e-3 * c.sim.thickness);
  EXPECT_LT(s.interior_force, 1e-6 * std::fabs(s.sxy) * 1e-3 * c.sim.thickness);
}

TEST(BondLattice, ReproducesElasticConstantsPlaneStress) {
  check_lattice(92e9, 0.21, Formulation::plane_stress);
  check_lattice(232e9, 0.3, Formulation::plane_stress);
}

TEST(BondLattice, ReproducesElasticConstantsPlaneStrain) {
  check_lattice(92e9, 0.2, Formulation::plane_strain);
}

TEST(BondLattice, PoissonRatioOutsideLatticeRangeIsRefused) {
  // nu = 0.3 in plane strain is nu* = 0.43 > 1/3: the shear spring would be negative.
  const Case c = lattice_case(4, 4, 1e-3, 232e9, 0.3, Formulation::plane_strain);
  EXPECT_THROW(Simulation{c}, InputError);
}

// A free square of discs spinning rigidly (v = w x r, spin = w) keeps its angular momentum
// sum m (x vy - y vx) + I w to round-off over many steps: bond forces are central pairs and the
// shear moments balance the shear couples exactly.
TEST(BondLattice, SpinningSquareKeepsAngularMomentum) {
  Case c = lattice_case(8, 8, 1e-3, 92e9, 0.21, Formulation::plane_stress);
  Simulation sim(c);
  Nodes& n = sim.model().nodes;
  const double w = 2000.0, cx = 4e-3, cy = 4e-3;
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), n.x);
  auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), n.v);
  auto spin = Kokkos::create_mirror_view_and_copy(HostSpace(), n.spin);
  for (int i = 0; i < n.count; ++i) {
    v(i, 0) = -w * (x(i, 1) - cy);
    v(i, 1) = w * (x(i, 0) - cx);
    spin(i) = w;
  }
  Kokkos::deep_copy(n.v, v);
  Kokkos::deep_copy(n.spin, spin);
  auto angular_momentum = [&]() {
    auto xh = Kokkos::create_mirror_view_and_copy(HostSpace(), n.x);
    auto vh = Kokkos::create_mirror_view_and_copy(HostSpace(), n.v);
    auto sh = Kokkos::create_mirror_view_and_copy(HostSpace(), n.spin);
    auto m = Kokkos::create_mirror_view_and_copy(HostSpace(), n.mass);
    auto I = Kokkos::create_mirror_view_and_copy(HostSpace(), n.inertia);
    double L = 0;
    for (int i = 0; i < n.count; ++i)
      L += m(i) * ((xh(i, 0) - cx) * vh(i, 1) - (xh(i, 1) - cy) * vh(i, 0)) + I(i) * sh(i);
    return L;
  };
  const double L0 = angular_momentum();
  for (int s = 0; s < 5000 && !sim.failed(); ++s) sim.step();
  EXPECT_FALSE(sim.failed());
  // Round-off: 5000 steps of sums over 81 discs in double precision.
  EXPECT_NEAR(angular_momentum(), L0, 1e-12 * std::fabs(L0));
}

}  // namespace
}  // namespace fracta

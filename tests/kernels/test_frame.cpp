// Frame packing (kernels/frame.hpp, bound to the frame's arrays by pack_frame_data): the arrays
// a frame shows, against values set by hand and the exact von Mises stress of uniaxial stress
// (sigma) and pure shear (sqrt(3) tau).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "host/model.hpp"
#include "host/simulation.hpp"
#include "kernels/frame.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

// The frame's arrays as fracta run packs them (pack_frame_data: count_frame, pack_frame).
FrameData pack(const Model& m) {
  FrameData f;
  FrameBuffers buffers;
  pack_frame_data(m, f, buffers);
  return f;
}

TEST(FramePacking, ElementsAverageTheirQuadraturePointsAndGiveVonMises) {
  Case c = test::rectangle_case(3, 2, 1e-3, 200e9, 0.3, 7800.0, Formulation::plane_strain);
  Model m = build_model(c);
  ASSERT_EQ(m.elements.active_count, 6);
  const int qp = m.elements.qp_per_element;
  const double sigma = 3e8, tau = 1e8;
  {
    auto stress = Kokkos::create_mirror_view_and_copy(HostSpace(), m.elements.stress);
    auto epeq = Kokkos::create_mirror_view_and_copy(HostSpace(), m.elements.epeq);
    auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.x);
    auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.v);
    for (int e = 0; e < 6; ++e)
      for (int g = 0; g < qp; ++g) {
        // Quadrature points differ (g - mean): the average is the element value.
        const double offset = (g - 0.5 * (qp - 1)) * 1e6;
        const double uniaxial[4] = {sigma, 0, 0, 0}, shear[4] = {0, 0, 0, tau},
                     general[4] = {1e6 * e + offset, -2e6 * e - offset, 5e5 * e, 4e5 * e};
        const double* s = e == 0 ? uniaxial : e == 1 ? shear : general;
        for (int k = 0; k < 4; ++k) stress(e * qp + g, k) = s[k];
        epeq(e * qp + g) = 0.01 * e + 1e-3 * g;
      }
    for (int i = 0; i < m.nodes.count; ++i) {
      x(i, 0) += 1e-6 * i;
      v(i, 1) = -2.0 * i;
    }
    Kokkos::deep_copy(m.elements.stress, stress);
    Kokkos::deep_copy(m.elements.epeq, epeq);
    Kokkos::deep_copy(m.nodes.x, x);
    Kokkos::deep_copy(m.nodes.v, v);
  }
  const FrameData p = pack(m);
  auto x0 = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.x0);
  auto conn = Kokkos::create_mirror_view_and_copy(HostSpace(), m.elements.nodes);
  for (int i = 0; i < m.nodes.count; ++i) {
    EXPECT_NEAR(p.node_displacement[2 * i], 1e-6 * i, 1e-18) << i;
    EXPECT_EQ(p.node_displacement[2 * i + 1], 0.0) << i;
    EXPECT_EQ(p.node_position[2 * i], x0(i, 0) + p.node_displacement[2 * i]) << i;
    EXPECT_EQ(p.node_velocity[2 * i + 1], -2.0 * i) << i;
  }
  // Uniaxial stress: von Mises = sigma, pressure = -sigma / 3. Pure shear: sqrt(3) tau, 0.
  EXPECT_NEAR(p.element_von_mises[0], sigma, 1e-6);
  EXPECT_NEAR(p.element_pressure[0], -sigma / 3, 1e-6);
  EXPECT_NEAR(p.element_von_mises[1], std::sqrt(3.0) * tau, 1e-6);
  EXPECT_NEAR(p.element_pressure[1], 0.0, 1e-9);
  for (int e = 0; e < 6; ++e) {
    EXPECT_EQ(p.element_id[e], e);
    for (int k = 0; k < 4; ++k) EXPECT_EQ(p.element_nodes[4 * e + k], conn(e, k));
    EXPECT_NEAR(p.element_plastic_strain[e], 0.01 * e + 1e-3 * 0.5 * (qp - 1), 1e-15) << e;
    if (e >= 2) {
      EXPECT_NEAR(p.element_stress[4 * e], 1e6 * e, 1e-6) << e;  // the offsets cancel
      EXPECT_NEAR(p.element_stress[4 * e + 1], -2e6 * e, 1e-6) << e;
      EXPECT_NEAR(p.element_pressure[e], -(1e6 * e - 2e6 * e + 5e5 * e) / 3, 1e-6) << e;
    }
  }
  EXPECT_TRUE(p.particle_node.empty());
  EXPECT_TRUE(p.bond_state.empty());
}

TEST(FramePacking, DiscsInNodeOrderAndBondsThatAreOrWereActiveInSlotOrder) {
  Case c = test::rectangle_case(4, 3, 1e-3, 200e9, 0.25, 7800.0, Formulation::plane_stress);
  c.bodies[0].method = BodyMethod::de;
  Model m = build_model(c);
  ASSERT_GT(m.bonds.count, 6);
  m.bonds.may_soften = true;  // the damage below stands for a cohesive law's
  auto state = Kokkos::create_mirror_view_and_copy(HostSpace(), m.bonds.state);
  auto fn = Kokkos::create_mirror_view_and_copy(HostSpace(), m.bonds.fn);
  auto damage = Kokkos::create_mirror_view_and_copy(HostSpace(), m.bonds.damage);
  for (int b = 0; b < m.bonds.count; ++b) {
    fn(b) = 10.0 * b;
    damage(b) = 0.001 * b;
  }
  state(1) = kBondBroken;
  state(4) = kBondInactive;
  Kokkos::deep_copy(m.bonds.state, state);
  Kokkos::deep_copy(m.bonds.fn, fn);
  Kokkos::deep_copy(m.bonds.damage, damage);
  auto ends = Kokkos::create_mirror_view_and_copy(HostSpace(), m.bonds.nodes);
  auto particle = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.particle);
  auto radius = Kokkos::create_mirror_view_and_copy(HostSpace(), m.nodes.radius);

  const FrameData p = pack(m);
  std::vector<int> discs;
  for (int i = 0; i < m.nodes.count; ++i)
    if (particle(i)) discs.push_back(i);
  EXPECT_EQ(p.particle_node, discs);
  for (std::size_t k = 0; k < discs.size(); ++k) EXPECT_EQ(p.particle_radius[k], radius(discs[k]));
  std::size_t k = 0;
  for (int b = 0; b < m.bonds.count; ++b) {
    if (state(b) == kBondInactive) continue;
    ASSERT_LT(k, p.bond_state.size());
    EXPECT_EQ(p.bond_nodes[2 * k], ends(b, 0));
    EXPECT_EQ(p.bond_nodes[2 * k + 1], ends(b, 1));
    EXPECT_EQ(p.bond_state[k], state(b));
    EXPECT_EQ(p.bond_normal_force[k], fn(b));
    EXPECT_EQ(p.bond_damage[k], state(b) == kBondBroken ? 1.0 : damage(b));
    ++k;
  }
  EXPECT_EQ(k, p.bond_state.size());
}

}  // namespace
}  // namespace fracta

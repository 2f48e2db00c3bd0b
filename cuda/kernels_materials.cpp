// CUDA check unit for src/kernels/materials.hpp: the material laws (every model through the
// update_stress and update_stress_with_state dispatches) and their helpers, called from a
// device kernel.
#include "kernels/materials.hpp"

namespace fracta::cuda_check {

void materials_kernels(const View<const MaterialLaw*>& laws, const View<double* [4]>& stress,
                       const View<double*>& epeq, const View<double*>& out) {
  const MaterialLaw host_law = make_material_law(kElastic, true, 7800.0, 2e11, 0.3);
  Kokkos::parallel_for(
      "fracta::cuda_check_materials", Kokkos::RangePolicy<ExecSpace>(0, stress.extent(0)),
      KOKKOS_LAMBDA(const int q) {
        const MaterialLaw m = laws(q % laws.extent(0));
        const double deps[3] = {1e-4, -2e-4, 5e-5};
        double s[4] = {stress(q, 0), stress(q, 1), stress(q, 2), stress(q, 3)};
        double ep = epeq(q);
        double state[kLawStateSize] = {0.0, 1e-3, 2e-3};
        const double work = update_stress(m, deps, s, ep) +
                            update_stress_with_state(m, deps, s, ep, state, 10.0) +
                            hjc_wave_speed(m, state) + law_wave_speed(m, state);
        for (int k = 0; k < 4; ++k) stress(q, k) = s[k];
        epeq(q) = ep;
        out(q) = work + elastic_energy_density(m, s) + m.wave_speed() + m.p_wave_modulus() +
                 host_law.wave_speed();
      });
}

}  // namespace fracta::cuda_check

// CUDA check unit for src/kernels/laws.hpp: every law of the lattice and of contact on the
// device, with T = double.
#include "kernels/laws.hpp"

namespace fracta::cuda_check {

void laws_kernels(const BondLaw& bond_law, const ContactLaw& contact_law,
                  const View<double*>& out) {
  Kokkos::parallel_for(
      "fracta::cuda_check_laws", Kokkos::RangePolicy<ExecSpace>(0, out.extent(0)),
      KOKKOS_LAMBDA(const int i) {
        const double u = 1e-3 * i;
        double u_plastic = 0.0, alpha = 0.0, force = 0.0;
        const SpringLaw spring = bond_law.springs();
        double r =
            SpringLaw::bilinear(1e6, u, spring.normal_yield_force(1e-4),
                                spring.hardening_stiffness(1e-4, 1e-3), u_plastic, alpha, force);
        r += SpringLaw::elastic_force(1e6, 1e-3 + u, 1e-3) +
             SpringLaw::elastic_increment(1e6, force, u);
        const FaceStrength face = bond_law.face();
        double sigma_n, tau;
        FaceStrength::traction(1e6 * i, -2e6, 3e5, 0.6, 0.8, sigma_n, tau);
        r += face.reaches(sigma_n, tau) ? 1.0 : 0.0;
        r += face.below_on_every_face(sigma_n, tau) ? 1.0 : 0.0;
        const CohesiveSoftening soft = bond_law.softening();
        double onset;
        const double lambda_f = soft.final_separation(force, 2.0, 1e6, 5e5, 1e-3,
                                                      soft.crack_area_factor[0], 1.25, onset);
        const double damage =
            CohesiveSoftening::damage(0.5 * (onset + lambda_f), onset, lambda_f, 0.0);
        double fn, fs;
        CohesiveSoftening::applied(force, 2.0, damage, fn, fs);
        r += CohesiveSoftening::work(force, fn, 2.0, fs, force, 0.0, 1e6, u) +
             soft.released_energy(force, 2.0, fn, fs, damage, 1e6, 5e5, u) +
             CohesiveSoftening::effective_separation(fn, fs, 1e6, 5e5) +
             CohesiveSoftening::undamaged(fs, damage);
        const double k = ContactLaw::series_stiffness(1e6, 2e6);
        const double cn = contact_law.normal_force(k, 2.0, 1e-6 * i, 1e-3);
        const double ct = contact_law.friction_force(cn, 1e-3, 3.0, 1e-7);
        out(i) = r + cn + ct + ContactLaw::elastic_energy(k, 1e-6 * i) +
                 ContactLaw::dissipation(k, 1e-6 * i, 1e-3, 1e-3, cn, ct, 2.0, 3.0, 1e-7);
      });
}

}  // namespace fracta::cuda_check

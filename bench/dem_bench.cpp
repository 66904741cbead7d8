// Cost per particle-step of the force-based DEM reference integrator (src/dem/dem_integrator.hpp)
// for a dilute gas of soft spheres: diameter 1, masses 1, Maxwellian velocities at kT = 1, a
// jittered lattice start, warmed up before timing.
//
//   dem_bench [D=3] [N=32000] [packing=0.05] [steps=2000] [model=dashpot|hertz] [k=1e4]
//             [skin=0.1 (fraction of the diameter)]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include "dem/dem_integrator.hpp"

namespace {

template <int D>
int run(long N, double packing, long steps, const kairos::SoftContactLaw& law, double skin) {
  using namespace kairos;
  const double R = 0.5;
  const double vol = D == 3 ? 4.0 / 3.0 * M_PI * R * R * R : M_PI * R * R;
  const double L = std::pow(static_cast<double>(N) * vol / packing, 1.0 / D);
  const long side = static_cast<long>(std::ceil(std::pow(static_cast<double>(N), 1.0 / D)));
  ParticleSystem<D> s;
  s.box.fill(L);
  s.species_names = {"A"};
  std::mt19937_64 rng(1);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> jitter(-0.1, 0.1);
  for (long i = 0; i < N; ++i) {
    Vec<D> r, v;
    long rest = i;
    for (int k = 0; k < D; ++k) {
      r[k] = (static_cast<double>(rest % side) + 0.5 + jitter(rng)) * L / static_cast<double>(side);
      rest /= side;
      v[k] = gauss(rng);
    }
    s.kinematics.push_back({r, v, 0.0, R});
    s.mass.push_back(1.0);
    s.species.push_back(0);
  }
  DemOptions opt;
  opt.reference_speed = 4.0;
  opt.skin = skin;
  DemIntegrator<D> dem(s, law, opt);
  dem.step(steps / 2);  // warm-up: leave the lattice
  const long builds0 = dem.neighbour_list_builds();
  double contacts = 0.0;
  const auto t0 = std::chrono::steady_clock::now();
  for (long n = 0; n < steps; n += 10) {
    dem.step(10);
    contacts += static_cast<double>(dem.contact_count());
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf(
      "D=%d N=%ld packing=%g model=%s skin=%g dt=%.4g steps=%ld: %.2f ns/particle-step "
      "(%.3f s; mean contacts/particle %.4f; list builds %ld)\n",
      D, N, packing, law.model == SoftModel::LinearDashpot ? "dashpot" : "hertz", skin, dem.dt(),
      steps, secs * 1e9 / (static_cast<double>(N) * static_cast<double>(steps)), secs,
      2.0 * contacts / (static_cast<double>(steps / 10) * static_cast<double>(N)),
      dem.neighbour_list_builds() - builds0);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const int D = argc > 1 ? std::atoi(argv[1]) : 3;
  const long N = argc > 2 ? std::atol(argv[2]) : 32000;
  const double packing = argc > 3 ? std::atof(argv[3]) : 0.05;
  const long steps = argc > 4 ? std::atol(argv[4]) : 2000;
  const std::string model = argc > 5 ? argv[5] : "dashpot";
  const double k = argc > 6 ? std::atof(argv[6]) : 1e4;
  const double skin = argc > 7 ? std::atof(argv[7]) : 0.1;
  const kairos::SoftContactLaw law =
      model == "hertz" ? kairos::SoftContactLaw::viscoelastic_hertz(k, 1e-3)
                       : kairos::SoftContactLaw::linear_dashpot(k, 0.2 * std::sqrt(0.5 * k));
  try {
    return D == 2 ? run<2>(N, packing, steps, law, skin) : run<3>(N, packing, steps, law, skin);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dem_bench: %s\n", e.what());
    return 1;
  }
}

// The soft-sphere proofs of issue 6 (docs/validation.md, "Soft spheres in the engine"): writes
// TSV files that examples/plot/plot_soft_proofs.py turns into figures.
//
//   soft_proofs divergence [--model hertz|dashpot] [--particles 1000] [--l-tilde 200]
//                          [--c-dis 0.1] [--t-end 8] [--samples 80] [--steps-per-contact 1000]
//                          [--no-tables] [--no-dem-check] [--seed 1] -o divergence.tsv
//   soft_proofs grazing [--l-tilde 100,1000] [--points 41] [--steps-per-contact 20000]
//                       -o grazing.tsv
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "soft_proofs.hpp"

namespace {

using namespace kairos;
using namespace kairos::proofs;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int divergence_command(const GasSpec& spec, const GasRunOptions& options, const std::string& out) {
  const auto t0 = std::chrono::steady_clock::now();
  GasRunOptions opt = options;
  int shown = 0;
  opt.progress = [&](double f) {
    if (f * 10.0 < shown + 1 - 1e-9) return;
    shown = static_cast<int>(f * 10.0 + 1e-9);
    std::fprintf(stderr, "%s: %3.0f %% (%.0f s)\n", model_name(spec.model), 100.0 * f,
                 seconds_since(t0));
  };
  const GasRun run = run_gas_divergence(spec, opt);
  std::FILE* f = std::fopen(out.c_str(), "w");
  if (f == nullptr) {
    std::fprintf(stderr, "cannot write %s\n", out.c_str());
    return 1;
  }
  std::fprintf(f, "# soft_proofs divergence: %s, N = %d, packing fraction %g, seed %llu\n",
               model_name(spec.model), spec.particles, spec.packing_fraction,
               static_cast<unsigned long long>(spec.seed));
  std::fprintf(f, "# law: stiffness %.10g, damping %.10g (l~ = %g, c_dis = %g at v_n = 1)\n",
               run.law.stiffness, run.law.damping, spec.l_tilde, spec.c_dis);
  std::fprintf(f, "# head-on at v_n = 1: t_c = %.6g, e = %.6f; DEM dt = %.6g (t_c / %.0f)\n",
               run.head_on_contact_time, run.head_on_restitution, run.dt,
               run.head_on_contact_time / run.dt);
  std::fprintf(f, "# mean free time over the run %.6g (t_c / tau = %.4g); tables %s (tol %g)\n",
               run.mean_free_time, run.head_on_contact_time / run.mean_free_time,
               options.tables ? "on" : "off", options.table_tolerance);
  std::fprintf(f,
               "# mapped: collisions %llu, soft contacts %llu, exception A %llu, exception B "
               "%llu, direct maps %llu; hard: collisions %llu; wall time %.1f s\n",
               static_cast<unsigned long long>(run.mapped.collisions),
               static_cast<unsigned long long>(run.mapped.soft_contacts),
               static_cast<unsigned long long>(run.mapped.soft_overlap_fallbacks),
               static_cast<unsigned long long>(run.mapped.soft_early_releases),
               static_cast<unsigned long long>(run.mapped.soft_direct_maps),
               static_cast<unsigned long long>(run.hard.collisions), seconds_since(t0));
  std::fprintf(f, "time\tcollisions_per_particle\tkinetic_energy\texception_a\texception_b");
  for (const char* m : {"mapped", "hard", "dem2dt"})
    std::fprintf(f, "\t%s_rms\t%s_max\t%s_median\t%s_n", m, m, m, m);
  std::fprintf(f, "\n");
  for (const GasSample& s : run.samples) {
    std::fprintf(f, "%.6g\t%.6g\t%.6g\t%llu\t%llu", s.time, s.collisions_per_particle,
                 s.kinetic_energy, static_cast<unsigned long long>(s.overlap_fallbacks),
                 static_cast<unsigned long long>(s.early_releases));
    for (const Divergence* d : {&s.mapped, &s.hard, &s.dem_coarse})
      std::fprintf(f, "\t%.4e\t%.4e\t%.4e\t%zu", d->rms, d->max, d->median, d->compared);
    std::fprintf(f, "\n");
  }
  std::fclose(f);
  const double tau = run.mean_free_time;
  std::printf(
      "%s, l~ = %g: t_c(v=1) = %.4g, tau = %.4g, dt = %.3g; first time (in tau) the divergence "
      "exceeds a level (rms / median)\n",
      model_name(spec.model), spec.l_tilde, run.head_on_contact_time, tau, run.dt);
  for (const double level : {1e-6, 1e-4, 1e-2, 1.0}) {
    std::printf("  %-6g radius:", level);
    for (auto m : {&GasSample::mapped, &GasSample::hard, &GasSample::dem_coarse}) {
      std::printf("  %s %6.3g / %6.3g",
                  m == &GasSample::mapped ? "mapped"
                  : m == &GasSample::hard ? "hard"
                                          : "DEM(2dt)",
                  first_time_above(run.samples, m, level) / tau,
                  first_time_above(run.samples, m, level, &Divergence::median) / tau);
    }
    std::printf("\n");
  }
  return 0;
}

int grazing_command(const std::vector<double>& l_tildes, int points, double steps_per_contact,
                    const std::string& out) {
  std::FILE* f = std::fopen(out.c_str(), "w");
  if (f == nullptr) {
    std::fprintf(stderr, "cannot write %s\n", out.c_str());
    return 1;
  }
  std::fprintf(f,
               "# soft_proofs grazing: masses 1 and 3, radii 0.4 and 0.6, v_n = 1; errors "
               "against direct integration (angles in degrees, offsets per l)\n");
  std::fprintf(f,
               "model\tl_tilde\tc_dis\tratio\te_head_on\tcontact_time\tdem_dt\te_exact\te_hard\t"
               "e_mapped\te_dem\tdeflection_exact\tangle_hard\tangle_mapped\tangle_dem\t"
               "offset_hard\toffset_mapped\toffset_dem\n");
  const double deg = 180.0 / M_PI;
  const Vec<3> box{12.0, 12.0, 12.0};
  for (const SoftModel model : {SoftModel::LinearDashpot, SoftModel::ViscoelasticHertz}) {
    for (const double lt : l_tildes) {
      for (int k = 0; k < points; ++k) {
        BinarySpec spec;
        spec.model = model;
        spec.l_tilde = lt;
        spec.c_dis = model == SoftModel::LinearDashpot ? 0.2 : 0.1;
        spec.ratio = std::pow(10.0, -2.0 + 4.0 * k / (points - 1));
        spec.dem_steps_per_contact = steps_per_contact;
        const BinaryResult r = binary_collision(spec);
        const double l = spec.radius_i + spec.radius_j;
        std::fprintf(
            f,
            "%s\t%g\t%g\t%.6g\t%.6f\t%.6g\t%.4g\t%.8f\t%.8f\t%.8f\t%.8f\t%.6f\t%.4e\t%.4e\t%.4e\t"
            "%.4e\t%.4e\t%.4e\n",
            model_name(model), lt, spec.c_dis, spec.ratio, r.head_on_restitution, r.contact_time,
            r.dem_dt, r.exact.e_eff, r.hard.e_eff, r.mapped.e_eff, r.dem.e_eff,
            r.exact.deflection * deg, direction_error(r.hard, r.exact) * deg,
            direction_error(r.mapped, r.exact) * deg, direction_error(r.dem, r.exact) * deg,
            position_error(r.hard, r.exact, box, l), position_error(r.mapped, r.exact, box, l),
            position_error(r.dem, r.exact, box, l));
        std::fflush(f);
        std::fprintf(stderr, "\r%s l~ = %g: %d/%d", model_name(model), lt, k + 1, points);
      }
      std::fprintf(stderr, "\n");
    }
  }
  std::fclose(f);
  // The numbers of docs/physics.md#hard-sphere-failure.
  std::printf("e_eff at v_t/v_n = 20 (docs/physics.md#hard-sphere-failure):\n");
  for (const SoftModel model : {SoftModel::LinearDashpot, SoftModel::ViscoelasticHertz}) {
    for (const double lt : {100.0, 1000.0}) {
      BinarySpec spec;
      spec.model = model;
      spec.l_tilde = lt;
      spec.c_dis = model == SoftModel::LinearDashpot ? 0.2 : 0.1;
      spec.ratio = 20.0;
      spec.dem_steps_per_contact = steps_per_contact;
      const BinaryResult r = binary_collision(spec);
      std::printf(
          "  %-7s l~ = %-5g head-on e %.4f: exact %+.5f mapped %+.5f DEM %+.5f hard %+.5f; "
          "direction error hard %.3f deg, mapped %.1e, DEM %.1e\n",
          model_name(model), lt, r.head_on_restitution, r.exact.e_eff, r.mapped.e_eff, r.dem.e_eff,
          r.hard.e_eff, direction_error(r.hard, r.exact) * deg,
          direction_error(r.mapped, r.exact) * deg, direction_error(r.dem, r.exact) * deg);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Kairos soft-sphere proofs (issue 6): trajectory divergence and grazing collisions"};
  app.require_subcommand(1);

  GasSpec gas;
  GasRunOptions gas_options;
  std::string model = "hertz", div_out = "divergence.tsv";
  bool no_tables = false, no_check = false;
  CLI::App* div = app.add_subcommand("divergence", "a dilute gas run by three methods");
  div->add_option("--model", model, "hertz | dashpot")->check(CLI::IsMember({"hertz", "dashpot"}));
  div->add_option("--particles", gas.particles, "N")->capture_default_str();
  div->add_option("--packing-fraction", gas.packing_fraction)->capture_default_str();
  div->add_option("--l-tilde", gas.l_tilde, "l~ at normal speed 1")->capture_default_str();
  div->add_option("--c-dis", gas.c_dis, "c_dis at normal speed 1 (default 0.1 hertz, 0.2 dashpot)");
  div->add_option("--seed", gas.seed)->capture_default_str();
  div->add_option("--t-end", gas_options.t_end)->capture_default_str();
  div->add_option("--samples", gas_options.samples)->capture_default_str();
  div->add_option("--steps-per-contact", gas_options.dem_steps_per_contact)->capture_default_str();
  div->add_option("--table-tolerance", gas_options.table_tolerance)->capture_default_str();
  div->add_flag("--no-tables", no_tables, "integrate every map directly");
  div->add_flag("--no-dem-check", no_check, "skip the DEM run at twice the time step");
  div->add_option("-o,--output", div_out)->capture_default_str();

  std::vector<double> l_tildes{100.0, 1000.0};
  int points = 41;
  double graze_steps = 20000.0;
  std::string graze_out = "grazing.tsv";
  CLI::App* graze = app.add_subcommand("grazing", "isolated binary collisions over v_t / v_n");
  graze->add_option("--l-tilde", l_tildes, "l~ values")->delimiter(',')->capture_default_str();
  graze->add_option("--points", points, "ratios from 0.01 to 100")->capture_default_str();
  graze->add_option("--steps-per-contact", graze_steps, "DEM")->capture_default_str();
  graze->add_option("-o,--output", graze_out)->capture_default_str();

  CLI11_PARSE(app, argc, argv);
  try {
    if (div->parsed()) {
      gas.model = model == "hertz" ? SoftModel::ViscoelasticHertz : SoftModel::LinearDashpot;
      if (div->count("--c-dis") == 0) gas.c_dis = model == "hertz" ? 0.1 : 0.2;
      gas_options.tables = !no_tables;
      gas_options.dem_check = !no_check;
      return divergence_command(gas, gas_options, div_out);
    }
    return grazing_command(l_tildes, points, graze_steps, graze_out);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}

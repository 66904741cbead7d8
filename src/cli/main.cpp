// The `kairos` command line.
//
//   kairos run CONFIG.toml [-o OUTDIR] [--set key=value ...] [--restart FILE] [--overwrite]
//   kairos steps CONFIG.toml [--set key=value ...] [--temperature KT] [-o DIR]
//   kairos table build|inspect|plot ...   (cli/table_command.hpp)
//   kairos sweep CONFIG.toml -o DIR --vary KEY=VALUES ...   (cli/sweep_command.hpp)
//
// User errors (config, files, impossible requests) print one line "kairos: error: ..." and exit
// with status 2; SIGINT/SIGTERM finish the current event, write every output and exit 130/143.
// Before the run has begun (loading the config, building tables) a signal ends the process at
// once with one line "kairos: interrupted ..." and the same status; nothing is written.
#include <malloc.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <new>
#include <optional>
#include <string>
#include <system_error>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "cli/replica_command.hpp"
#include "cli/sweep_command.hpp"
#include "cli/table_command.hpp"
#include "core/error.hpp"
#include "core/stop_flag.hpp"
#include "interactions/potential_spec.hpp"
#include "io/atomic_file.hpp"
#include "io/config.hpp"
#include "io/config_keys.hpp"
#include "io/progress.hpp"
#include "run/config_ranges.hpp"
#include "run/provenance.hpp"
#include "run/run.hpp"

namespace {

volatile std::sig_atomic_t g_signal = 0;

extern "C" void on_signal(int sig) {
  g_signal = sig;
  kairos::request_stop();
}

void install_signal_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND;  // a second signal kills at once
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  // A file size limit (ulimit -f) or a closed pipe on the console would kill the process in
  // the middle of a write (a torn row, no summary, no restart file). Ignored, the write fails
  // with EFBIG or EPIPE instead: an output's failure stops the run with every other output
  // written (docs/guarantees.md); the console's is ignored.
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGXFSZ, &ignore, nullptr);
  sigaction(SIGPIPE, &ignore, nullptr);
}

void print_summary(const kairos::RunOutcome& outcome) {
  const auto& s = outcome.summary;
  auto number = [](const nlohmann::json& where, const char* key) -> std::optional<double> {
    if (!where.contains(key) || !where[key].is_number()) return std::nullopt;
    return where[key].get<double>();
  };
  auto num = [&](const char* key) { return number(s, key).value_or(std::nan("")); };
  // Undefined in this run (null in summary.json): "n/a" and the reason.
  auto why = [&](const std::string& name) {
    const auto& u = s.contains("undefined") ? s["undefined"] : nlohmann::json::object();
    return u.contains(name) ? fmt::format("n/a ({})", u[name].get<std::string>())
                            : std::string("n/a");
  };
  // A blocked error bar whose run was too short for the correlation time (docs/outputs.md).
  auto unreliable = [](const nlohmann::json& where, const char* key) {
    return where.contains(key) && where[key].is_boolean() && !where[key].get<bool>()
               ? std::string(" (error bar unreliable: run too short)")
               : std::string();
  };
  const bool dem = s.value("integrator", "event") == "dem";
  const bool early = outcome.interrupted || !outcome.error.empty();
  fmt::print("\nKairos run {} ({})\n", early ? "stopped early" : "finished",
             s["stop_reason"].get<std::string>());
  fmt::print("  particles            {} in {}D, packing fraction {:.6g}\n",
             s["particles"].get<std::uint64_t>(), s["dimension"].get<int>(),
             num("packing_fraction"));
  fmt::print("  {:<20} {} ({} collisions) in {} wall\n", dem ? "time steps" : "events",
             s["events"].get<std::uint64_t>(), s["collisions"].get<std::uint64_t>(),
             kairos::format_duration(num("wall_seconds")));
  fmt::print("  speed                {:.3g} M {}/s, {:.3g} M collisions/s\n",
             num("events_per_second") / 1e6, dem ? "steps" : "events",
             num("collisions_per_second") / 1e6);
  fmt::print("  simulated time       {:.6g}\n", num("sim_time"));
  fmt::print("  temperature          {:.10g}\n", num("temperature"));
  const auto& z = s["compressibility"];
  if (const auto zm = number(z, "mean")) {
    const auto ze = number(z, "stderr");
    fmt::print("  compressibility Z    {:.5f} +- {}{}\n", *zm,
               ze ? fmt::format("{:.5f}", *ze) : std::string("n/a"),
               ze ? unreliable(z, "stderr_reliable") : std::string());
  } else {
    fmt::print("  compressibility Z    {}\n", why("compressibility"));
  }
  if (const auto mft = number(s, "mean_free_time"))
    fmt::print("  mean free time       {:.6g}\n", *mft);
  else
    fmt::print("  mean free time       {}\n", why("mean_free_time"));
  if (s.contains("granular")) {
    const auto& g = s["granular"];
    auto gnum = [&](const char* key) { return number(g, key).value_or(std::nan("")); };
    auto flag = [&](const char* key) { return !g.contains(key) || g[key].get<bool>(); };
    if (flag("rotating"))
      fmt::print("  rotational temp.     {:.6g}\n", gnum("rotational_temperature"));
    if (flag("dissipative")) {
      if (const auto a2 = number(g, "sonine_a2"))
        fmt::print("  Sonine a2            {:.4f}\n", *a2);
      fmt::print("  dissipated           {:.6g} in collisions, {:.6g} at walls\n",
                 gnum("dissipated_in_collisions"), gnum("dissipated_at_walls"));
    }
    if (flag("moving_walls")) fmt::print("  work by walls        {:.6g}\n", gnum("work_by_walls"));
    if (g.value("driven", false))
      fmt::print("  work by driving      {:.6g} ({} kicks)\n", gnum("work_by_driving"),
                 g.value("driving_kicks", std::uint64_t{0}));
    if (const auto balance = number(g, "energy_balance_relative"))
      fmt::print("  energy balance       {:.3g} (rel.)\n", *balance);
    else
      fmt::print("  energy balance       {}\n", why("granular.energy_balance_relative"));
    if (s.contains("shear")) {
      const auto& sh = s["shear"];
      fmt::print("  shear stress P_xy    {:.6g} +- {:.2g} at shear rate {:.6g}{}\n",
                 number(sh, "shear_stress").value_or(std::nan("")),
                 number(sh, "shear_stress_stderr").value_or(std::nan("")),
                 number(sh, "shear_rate").value_or(std::nan("")),
                 unreliable(sh, "shear_stress_stderr_reliable"));
      fmt::print("  viscosity            {:.6g} +- {:.2g}{}\n",
                 number(sh, "viscosity").value_or(std::nan("")),
                 number(sh, "viscosity_stderr").value_or(std::nan("")),
                 unreliable(sh, "shear_stress_stderr_reliable"));
    }
  } else {
    fmt::print("  energy drift (rel.)  {:.3g}\n", num("energy_drift_relative"));
  }
  if (s.contains("stepped")) {
    const auto& st = s["stepped"];
    fmt::print("  potential energy/N   {:.6g} +- {:.2g}{}\n",
               number(st, "potential_energy_per_particle_mean").value_or(std::nan("")),
               number(st, "potential_energy_per_particle_stderr").value_or(std::nan("")),
               unreliable(st, "potential_energy_per_particle_stderr_reliable"));
    fmt::print("  pair events          {} core, {} step crossings, {} step bounces\n",
               st["core_collisions"].get<std::uint64_t>(),
               st["step_crossings"].get<std::uint64_t>(), st["step_bounces"].get<std::uint64_t>());
  }
  if (s.contains("soft")) {
    const auto& so = s["soft"];
    fmt::print(
        "  soft contacts        {} mapped, {} placed over a third body (A), {} released "
        "early (B), {} maps integrated directly\n",
        so["mapped_contacts"].get<std::uint64_t>(),
        so["exception_a_overlap_fallbacks"].get<std::uint64_t>(),
        so["exception_b_early_releases"].get<std::uint64_t>(),
        so["direct_maps"].get<std::uint64_t>());
  }
  fmt::print("  max overlap          {:.3g}\n", num("max_overlap"));
  fmt::print("  peak memory          {:.1f} MiB\n", num("peak_rss_bytes") / 1048576.0);
  std::string files;
  if (s.contains("outputs"))
    for (const auto& f : s["outputs"]) files += (files.empty() ? "" : ", ") + f.get<std::string>();
  fmt::print("  outputs              {}/ ({})\n", outcome.directory.string(), files);
}

// `kairos steps`: the step table of every [[potential]] (per species pair) and [[bond]] of the
// config, for the species' diameters as contact distances, with B2 at kT; with a directory,
// each table and its continuous curve as TSV files for examples/plot/plot_steps.py.
void print_step_tables(const kairos::Config& config, double kT, const std::string& dir) {
  const auto& species = config.system.species;
  const int dim = config.system.dimension;
  struct Item {
    std::string label;
    const kairos::PotentialSpec* spec;
    double core;
    double reduced_mass = std::nan("");  // spring_dashpot's restitution needs it
  };
  std::vector<Item> items;
  for (std::size_t p = 0; p < config.potentials.size(); ++p) {
    const auto& pc = config.potentials[p];
    for (std::size_t a = 0; a < species.size(); ++a) {
      for (std::size_t b = a; b < species.size(); ++b) {
        const bool named = pc.species.empty() ||
                           (pc.species[0] == species[a].name && pc.species[1] == species[b].name) ||
                           (pc.species[0] == species[b].name && pc.species[1] == species[a].name);
        if (!named) continue;
        items.push_back({fmt::format("potential{}_{}_{}", p, species[a].name, species[b].name),
                         &pc.potential, 0.5 * (species[a].diameter + species[b].diameter),
                         species[a].mass * species[b].mass / (species[a].mass + species[b].mass)});
      }
    }
  }
  double dmax = 0.0;
  for (const auto& sp : species) dmax = std::max(dmax, sp.diameter);
  for (std::size_t k = 0; k < config.bonds.size(); ++k)
    items.push_back({fmt::format("bond{}_{}", k, config.bonds[k].type), &config.bonds[k].potential,
                     dmax, std::nan("")});
  if (items.empty()) throw kairos::InputError("the config has no [[potential]] and no [[bond]]");
  // The ranges a run checks against its box (no box here: lengths up to 1e6 diameters).
  const kairos::RangeScales scales = kairos::range_scales(config);
  for (std::size_t p = 0; p < config.potentials.size(); ++p) {
    kairos::check_potential_ranges(config.potentials[p].potential, fmt::format("potential[{}]", p),
                                   scales);
  }
  for (std::size_t k = 0; k < config.bonds.size(); ++k)
    kairos::check_potential_ranges(config.bonds[k].potential, fmt::format("bond[{}]", k), scales);
  for (const Item& item : items) {
    kairos::throw_if_stop_requested();
    const kairos::StepTable table =
        kairos::make_step_table(*item.spec, item.core, dim, item.reduced_mass);
    const kairos::ContinuousPotential curve = kairos::continuous_potential(*item.spec);
    const bool has_curve = !curve.name.empty();
    const std::string report =
        kairos::step_table_report(table, has_curve ? &curve : nullptr, kT, dim);
    fmt::print("# {} ({}), contact distance {}\n{}\n", item.label, item.spec->kind, item.core,
               report);
    if (dir.empty()) continue;
    std::filesystem::create_directories(dir);
    kairos::write_text_atomically(std::filesystem::path(dir) / (item.label + ".tsv"), report);
    if (has_curve) {
      kairos::write_text_atomically(
          std::filesystem::path(dir) / (item.label + "_curve.tsv"),
          kairos::continuous_curve_tsv(curve, table.core(), table.cutoff() * 1.05));
    }
  }
}

// Interrupted: a signal or run.max_wall_seconds stopped the setup, before anything was run or
// written. A signal exits with 128 + its number, as a stopped run does; the wall-time limit is
// the user's to raise (status 2).
int report_interrupted_setup(const kairos::Interrupted& e) {
  if (e.cause() == kairos::Interrupted::Cause::kWallTime) {
    std::fprintf(stderr,
                 "kairos: error: run.max_wall_seconds: %s before the run could start (during its "
                 "setup); nothing was run: raise the limit, or build the soft-sphere tables "
                 "beforehand with 'kairos table build --config CONFIG'\n",
                 e.what());
    return 2;
  }
  const int sig = g_signal != 0 ? static_cast<int>(g_signal) : SIGINT;
  std::fprintf(stderr, "kairos: interrupted by %s before the run started; nothing was written\n",
               sig == SIGTERM  ? "SIGTERM"
               : sig == SIGINT ? "SIGINT"
                               : strsignal(sig));
  return 128 + sig;
}

}  // namespace

int main(int argc, char** argv) {
  // Allocations of 2 MiB and more are mappings of their own, given back when freed. glibc's
  // default threshold slides up to 32 MiB after the first large free, and every later
  // temporary of an output (whole-state copies, the block order) then stayed in the heap: ~40
  // bytes per particle of the whole process's peak at N = 10^6 (docs/performance.md).
  mallopt(M_MMAP_THRESHOLD, 2 << 20);
  CLI::App app{
      "Kairos: event-driven molecular dynamics of hard, granular, stepped-potential and soft "
      "spheres "
      "(3D) and disks (2D).\n"
      "Configuration keys are documented in docs/config.md."};
  app.set_version_flag("--version", std::string("kairos ") + KAIROS_VERSION);
  app.require_subcommand(1);
  app.footer(
      "Usage of run: kairos run CONFIG.toml [-o OUTDIR] [--set key=value ...] [--restart FILE] "
      "[--overwrite]\n"
      "Usage of steps: kairos steps CONFIG.toml [--set key=value ...] [--temperature KT] [-o DIR]\n"
      "Usage of table: kairos table build|inspect|plot ... (soft-sphere collision map tables)\n"
      "Usage of sweep: kairos sweep CONFIG.toml -o SWEEPDIR --vary KEY=VALUES ... [--workers N] "
      "(a grid of runs; under mpirun across ranks)\n"
      "Usage of replica-exchange: kairos replica-exchange CONFIG.toml -o DIR --temperatures "
      "A:B:N:log --interval DT --exchanges N (parallel tempering)\n"
      "Usage of config-keys: kairos config-keys [--markdown] (every config key, declared once)\n"
      "  -o,--output OUTDIR   output directory (overrides output.directory)\n"
      "  --set key=value      override a config key (repeatable)\n"
      "  --restart FILE       continue from a restart file (OUTDIR/restart.gsd)\n"
      "See 'kairos run --help' for details.");

  std::string config_path, outdir, restart;
  std::vector<std::string> overrides;
  auto* run = app.add_subcommand("run", "Run a simulation described by a TOML config file.");
  run->add_option("config", config_path, "TOML configuration file (see docs/config.md)")
      ->required();
  auto* output_option = run->add_option(
      "-o,--output", outdir, "Output directory (overrides output.directory; created if missing)");
  run->add_option("--set", overrides,
                  "Override a config key, dotted path and TOML value, e.g. "
                  "--set system.packing_fraction=0.3 --set system.lattice=sc (repeatable)")
      ->take_all()
      ->allow_extra_args(false);  // one value per --set, so `--set k=v CONFIG` keeps CONFIG
  auto* restart_option = run->add_option(
      "--restart", restart,
      "Continue from a restart file (OUTDIR/restart.gsd) bit-identically: a finished "
      "equilibration is not repeated (an interrupted one is completed), then "
      "run.collisions_per_particle more collisions per particle (or run.time more simulated "
      "time) are simulated");
  bool overwrite = false;
  run->add_flag("--overwrite", overwrite,
                "Replace the outputs an earlier run left in OUTDIR (refused otherwise); with "
                "--restart, those of another run (not the restart file's lineage)");
  run->footer(
      "Outputs in OUTDIR: config.toml, thermo.tsv, trajectory.gsd, restart.gsd, summary.json.\n"
      "SIGINT/SIGTERM stop after the current event and still write every output.");

  std::string steps_config;
  std::vector<std::string> steps_overrides;
  double steps_kT = 0.0;
  std::string steps_dir;
  auto* steps = app.add_subcommand(
      "steps", "Print the step tables of a config's potentials and bonds with their B2(T).");
  steps->add_option("config", steps_config, "TOML configuration file")->required();
  steps->add_option("--set", steps_overrides, "Override a config key (repeatable)")
      ->take_all()
      ->allow_extra_args(false);
  steps->add_option("--temperature", steps_kT, "kT for B2 (default: system.temperature)");
  steps->footer(
      "Prints, for every [[potential]] (each species pair it covers) and [[bond]] of the config, "
      "the step table for the species' contact distances with B2 at kT, beside the continuous "
      "potential's; -o DIR also writes NAME.tsv and NAME_curve.tsv per table for "
      "examples/plot/plot_steps.py.");
  steps->add_option("-o,--output", steps_dir,
                    "Also write each table and its continuous curve as TSV files in this directory "
                    "(for examples/plot/plot_steps.py)");

  bool keys_markdown = false;
  auto* config_keys = app.add_subcommand(
      "config-keys", "List every config key: path, type, default, range and meaning.");
  config_keys->add_flag(
      "--markdown", keys_markdown,
      "As one markdown table (the declarations docs/config.md is checked against)");

  const auto table_command = kairos::cli::add_table_command(app);
  const auto sweep_command = kairos::cli::add_sweep_command(app);
  const auto replica_command = kairos::cli::add_replica_command(app);

  // Usage errors are user errors too: one line "kairos: error: ...", exit status 2 (not CLI11's
  // own codes and two-line message). --help and --version still print and exit 0.
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    std::string message = e.what();
    for (char& c : message) {
      if (c == '\n' || c == '\r') c = ' ';
    }
    std::fprintf(stderr, "kairos: error: %s (see 'kairos --help' and 'kairos run --help')\n",
                 message.c_str());
    return 2;
  }

  // Before anything is read: a config or a table can take long, and SIGINT must end that too.
  install_signal_handlers();
  try {
    // An empty value (e.g. from an unset shell variable) is an error, not "option absent": a
    // silently fresh run would overwrite the outputs it was meant to continue.
    if (output_option->count() > 0 && outdir.empty()) {
      throw kairos::InputError("-o/--output: the output directory must not be empty");
    }
    if (restart_option->count() > 0 && restart.empty()) {
      throw kairos::InputError("--restart: the restart file name must not be empty");
    }
    if (table_command->parsed()) return table_command->run();
    if (sweep_command->parsed()) {
      return sweep_command->run(argc, argv, [] { return g_signal != 0 ? int{g_signal} : SIGINT; });
    }
    if (replica_command->parsed()) {
      return replica_command->run(argc, argv,
                                  [] { return g_signal != 0 ? int{g_signal} : SIGINT; });
    }
    if (config_keys->parsed()) {
      std::fputs((keys_markdown ? kairos::keys_markdown() : kairos::keys_text()).c_str(), stdout);
      return 0;
    }
    if (steps->parsed()) {
      const kairos::Config config = kairos::load_config(steps_config, steps_overrides);
      if (steps_kT < 0.0 || !std::isfinite(steps_kT))
        throw kairos::InputError("--temperature: must be a finite number > 0");
      print_step_tables(config, steps_kT > 0.0 ? steps_kT : config.system.temperature, steps_dir);
      return 0;
    }
    kairos::Config config = kairos::load_config(config_path, overrides);
    if (!outdir.empty()) config.output.directory = outdir;
    const std::optional<std::filesystem::path> restart_file =
        restart.empty() ? std::nullopt : std::optional<std::filesystem::path>(restart);
    kairos::RunOptions options;
    options.overwrite = overwrite;
    options.command_line = kairos::shell_command_line(std::vector<std::string>(argv, argv + argc));
    // run.max_wall_seconds from now on, so that a long table build stops too.
    const kairos::ScopedStopDeadline setup_limit(config.run.max_wall_seconds);
    const kairos::RunOutcome outcome = kairos::run_simulation(config, restart_file, options);
    try {
      print_summary(outcome);
    } catch (const std::system_error&) {
      // The console is gone (a closed pipe): the outputs are written, the run's status stands.
    }
    if (!outcome.error.empty()) {
      std::fprintf(stderr, "kairos: error: %s\n", outcome.error.c_str());
      return 2;
    }
    if (outcome.interrupted && g_signal != 0) return 128 + g_signal;
    return 0;
  } catch (const kairos::InputError& e) {
    std::fprintf(stderr, "kairos: error: %s\n", e.what());
    return 2;
  } catch (const kairos::Interrupted& e) {
    return report_interrupted_setup(e);
  } catch (const std::bad_alloc&) {
    // The up-front estimate (core/memory_budget) did not foresee it: a limit it cannot see
    // (ulimit -v), or a structure that grows during the run (the capture map of long-ranged
    // stepped potentials). Not a bug: the user can give the run more memory or make it smaller.
    std::fprintf(stderr,
                 "kairos: error: out of memory: the run needs more memory than this process may "
                 "use (check `ulimit -v` and the machine's free memory); run fewer particles, a "
                 "shorter potential cut-off, or on a larger machine\n");
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kairos: internal error: %s\n", e.what());
    return 3;
  }
}

// The setup chain, in one place: state -> environment -> tables -> integrator. `kairos run`
// (run/run_driver.hpp), the Python module's Simulation (run/simulation.hpp) and `kairos table
// build --config` (cli/table_command.cpp) all start here, so that they build the same state, the
// same contact laws and the same soft-sphere tables, bit for bit.
//
// 1. start_run: the start state (run/start_state.hpp) and, after --restart, how the changed
//    configuration is used (run/restart_plan.hpp): the effective configuration is then the
//    plan's, and a re-predicted state is brought to the present on its old trajectories.
// 2. make_environment (run/environment_setup.hpp): contact laws, walls, fields, potentials.
// 3. start_tables: the soft-sphere map tables the event integrator looks contacts up in.
// 4. start_integrator: the integrator of run.integrator (and run.event_queue) over the state.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "core/particle_system.hpp"
#include "io/config.hpp"
#include "model/environment.hpp"
#include "run/compression.hpp"
#include "run/integrator.hpp"
#include "run/restart_plan.hpp"
#include "run/run_progress.hpp"
#include "run/soft_tables_setup.hpp"

namespace kairos {

// What a run starts from.
template <int D>
struct RunStart {
  // The effective configuration: after a restart, the configuration as it is used
  // (RestartPlan::used), which config.toml and the restart files record.
  Config config;
  std::optional<std::filesystem::path> restart_file;
  RunProgress resumed;              // what the restart file recorded (defaults for a new run)
  std::optional<RestartPlan> plan;  // a restart: how it uses the changed configuration
  std::mt19937_64 rng;              // the run's RNG, after drawing the start state
  ParticleSystem<D> state;
  // A new run's compression ([compress], or a random start denser than insertion reaches).
  std::optional<CompressionReport> compression;

  bool restarted() const { return restart_file.has_value(); }
  // A restart whose stored predictions stay valid: continued bit-identically.
  bool resumes() const { return plan && !plan->repredict; }
  std::string restart_name() const { return restart_file ? restart_file->string() : ""; }
};

// Step 1. `integrator`: the integrator that will run it ("event", "dem"); a restart file
// continues only under the one that wrote it. InputError for anything the user must fix.
template <int D>
RunStart<D> start_run(const Config& config,
                      const std::optional<std::filesystem::path>& restart_file,
                      std::string_view integrator);

// Step 3. Sees (contact, fraction done) while a table is built.
using TableProgress = std::function<void(const std::string& contact, double fraction)>;
// The settings of the tables of `config` (a continued run: the speeds its restart file
// recorded, so that it uses the same tables).
SoftTableSettings soft_table_settings(const Config& config, const RunProgress& resumed);
// Attaches them to `environment` (soft spheres with soft.tables only; else none).
template <int D>
std::vector<SoftTableUse> start_tables(Environment<D>& environment, const RunStart<D>& start,
                                       const TableProgress& progress = {});

// Steps 2 to 4: the integrator that runs `start` (which it takes over). InputError for what
// the user must fix; for a restarted state named as restart_setup_error says.
template <int D>
std::unique_ptr<Integrator<D>> start_integrator(RunStart<D>&& start,
                                                const TableProgress& progress = {});

// What the event engine keeps beyond what the configuration asks for (the Python module's
// Simulation): image counters (EngineOptions::track_images), the Helfand moments
// (track_helfand; for a system transport_obstacle() lets through only).
struct EngineTracking {
  bool images = false;
  bool helfand = false;
};

// Steps 2 to 4 for the event engine with a given queue (the Python module's Simulation).
template <int D, class Queue>
class EventEngineAdapter;
template <int D, class Queue>
std::unique_ptr<EventEngineAdapter<D, Queue>> start_event_engine(
    RunStart<D>&& start, const TableProgress& progress = {}, const EngineTracking& tracking = {});

// An InputError from setting up a restored state (its environment, the engine, the overlap
// check) as reported: naming the restart file and, under new physics, the keys that changed.
InputError restart_setup_error(const InputError& e, const std::filesystem::path& restart_file,
                               const RestartPlan& plan);

// The note on stderr about a restart whose configuration changed (once it is set up).
void print_restart_note(const RestartPlan& plan, const std::string& restart_file);

}  // namespace kairos

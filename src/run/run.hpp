// One invocation of `kairos run`: configuration -> initial state -> integrator -> outputs (the
// run driver, run/run_driver.hpp, for either integrator).
//
// Phases: equilibration (skipped on restart), then production, each measured in collisions per
// particle c = 2 N_coll / N or in simulated time (run.time, run.equilibration_time). Outputs in the
// output directory: config.toml (the effective configuration), thermo.tsv, trajectory.gsd,
// restart.gsd, summary.json (see docs/outputs.md).
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/stop_flag.hpp"  // request_stop(), clear_stop_request(): stop a running simulation
#include "io/config.hpp"

namespace kairos {

struct RunOutcome {
  nlohmann::json summary;
  std::filesystem::path directory;
  bool interrupted = false;  // stopped by a signal or the wall-time limit (outputs still written)
  // Non-empty: the run stopped because it could not go on (a frozen clock, ...); every output is
  // written, and the message says why and what to change. The CLI prints it as an error.
  std::string error;
};

// How one invocation treats its output directory (run/output_directory.hpp).
struct RunOptions {
  bool overwrite = false;  // a new run may replace the outputs an earlier run left there
  // How the run was invoked, for its provenance (summary.json, config.toml); "": not said.
  std::string command_line;
};

// Runs the whole simulation. Throws InputError for anything the user must fix.
RunOutcome run_simulation(const Config& config,
                          const std::optional<std::filesystem::path>& restart_file = {},
                          const RunOptions& options = {});

}  // namespace kairos

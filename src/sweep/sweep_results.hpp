// What a sweep's run directories hold, and the sweep's table of results (docs/sweeps.md):
// results.tsv (one row per run: its values, its state, every summary.json key flattened to a
// dotted column) and results.json (the same runs with their summaries whole).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sweep/sweep_grid.hpp"

namespace kairos {

// A run's state, read from its directory.
enum class SweepRunState {
  kNotRun,    // no outputs
  kFinished,  // summary.json with a final stop_reason (completed, at_rest, no_more_events)
  kStopped,   // interrupted (signal, wall-time limit, killed): restart.gsd continues it
  kFailed,    // it ended in an error (summary.json's error, or the last "kairos: error:" line)
};

struct SweepRunRecord {
  SweepRunState state = SweepRunState::kNotRun;
  std::string error;         // kFailed: the message
  nlohmann::json summary;    // summary.json (null if none)
  bool has_restart = false;  // restart.gsd present
};

// The name of the file in a run's directory that holds its console (stdout and stderr of each
// attempt, appended).
inline constexpr const char* kSweepConsoleFile = "console.log";

SweepRunRecord read_sweep_run(const std::filesystem::path& run_directory);

const char* state_name(SweepRunState state);

// Writes results.tsv and results.json into the sweep directory (each atomically); returns each
// point's state.
std::vector<SweepRunState> write_sweep_results(const std::filesystem::path& sweep_directory,
                                               const std::vector<SweepAxis>& axes,
                                               const std::vector<SweepPoint>& points);

// summary.json flattened: nested objects and arrays of numbers to dotted keys
// ("compressibility.mean", "pressure_tensor.0.1"), arrays of strings joined by commas.
std::vector<std::pair<std::string, std::string>> flattened_summary(const nlohmann::json& summary);

}  // namespace kairos

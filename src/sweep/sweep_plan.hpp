// A sweep as planned (docs/sweeps.md): the config, the overrides every run shares, the grid, and
// the directory that holds one run directory per point with sweep.json (what the sweep is, so
// that the same command continues it and a different one is refused) and the results table.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "sweep/sweep_grid.hpp"

namespace kairos {

struct SweepPlan {
  std::filesystem::path config;        // as given (children run it from the same directory)
  std::string config_text;             // its text when the sweep was planned
  std::vector<std::string> overrides;  // --set, shared by every run
  std::vector<SweepAxis> axes;
  std::vector<SweepPoint> points;
  std::filesystem::path directory;

  // The arguments of `kairos run` for one point, after the program name: the sweep's copy of
  // the config (run_config()), -o DIR, the shared overrides, then the point's.
  std::vector<std::string> run_arguments(const SweepPoint& point) const;
  // SWEEPDIR/sweep-config.toml: the config text as planned, which every run reads (an edit of
  // the original during a sweep changes no run; relative paths in it are the working
  // directory's, as for the original).
  std::filesystem::path run_config() const { return directory / "sweep-config.toml"; }
  std::filesystem::path run_directory(const SweepPoint& point) const {
    return directory / point.name;
  }
};

// Reads the config and checks every point's configuration as its run will read it (InputError
// naming the run and its values). Refuses varying output.directory, a key both set and varied.
SweepPlan plan_sweep(const std::filesystem::path& config, const std::vector<std::string>& overrides,
                     const std::vector<std::string>& vary, const std::filesystem::path& directory);

// Creates the directory, or finds it; InputError if it cannot be made.
void make_sweep_directory(const SweepPlan& plan);

// With the directory locked: writes sweep.json and the config's copy, or checks that the
// sweep.json there describes this sweep (the same config text, --set list and grid):
// InputError naming what differs.
void claim_sweep_directory(const SweepPlan& plan);

// Holds an exclusive lock on the sweep directory (flock on .kairos-sweep.lock) while alive;
// InputError if another sweep holds it. The runs inherit the lock: a sweep killed outright
// keeps its directory locked until its last run (sent SIGTERM by the kernel) has ended.
class SweepDirectoryLock {
 public:
  explicit SweepDirectoryLock(const std::filesystem::path& directory);
  ~SweepDirectoryLock();
  SweepDirectoryLock(const SweepDirectoryLock&) = delete;
  SweepDirectoryLock& operator=(const SweepDirectoryLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace kairos

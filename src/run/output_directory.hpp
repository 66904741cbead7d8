// The output directory of a run, claimed for it: created if missing, locked against every other
// run for as long as this one lasts (flock on OUTDIR/.kairos.lock: two runs writing one
// directory would overwrite each other's files), and never holding another run's outputs
// unless the user asks to overwrite them.
//
// Lineage: every run has a random run id (kairos/run/id in its restart files, run_id in
// summary.json), kept by every run continued from its restart files. A continued run may append
// to the outputs in a directory only when they are of its own lineage (the directory's
// restart.gsd and summary.json carry its id); outputs of another run are refused unless
// overwritten, so that the files of two runs are never mixed.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "run/run_progress.hpp"

namespace kairos {

// The two files of a run directory that are read by more than their writers: the directory's
// guard reads the lineage from them, the sweep reads them to tell a finished run from one to
// continue. Their writers (run/outputs/restart_output.hpp, run/outputs/run_summary.hpp) declare
// them from here.
inline constexpr std::string_view kRestartFileName = "restart.gsd";
inline constexpr std::string_view kSummaryFileName = "summary.json";

// A run continued from a restart file (--restart).
struct RestartLineage {
  std::filesystem::path restart_file;
  std::string run_id;  // of the restart file ("": an older file that records none)
};

class OutputDirectory {
 public:
  // `continuing`: a restart, which appends to the outputs found there if they are of its own
  // lineage (continues_outputs()), else refuses them (InputError naming the directory and both
  // runs) unless `overwrite`. An empty directory is fine. A restart file that records no run id
  // (older files) continues the outputs of its own directory, as before run ids.
  // `overwrite`: the outputs of an earlier (or another) run are removed first.
  // InputError naming the directory if it cannot be created, is in use by another run, or
  // holds another run's outputs.
  OutputDirectory(const std::filesystem::path& dir, const std::optional<RestartLineage>& continuing,
                  bool overwrite);
  ~OutputDirectory();
  OutputDirectory(OutputDirectory&& other) noexcept;
  OutputDirectory& operator=(OutputDirectory&&) = delete;
  OutputDirectory(const OutputDirectory&) = delete;
  OutputDirectory& operator=(const OutputDirectory&) = delete;

  const std::filesystem::path& path() const { return dir_; }
  // A restart whose lineage's outputs are in the directory: thermo.tsv and trajectory.gsd are
  // cut back to the restart point and appended to. False: the directory holds no outputs (now).
  bool continues_outputs() const { return continues_; }

 private:
  void release() noexcept;
  std::filesystem::path dir_;
  int lock_fd_ = -1;
  bool continues_ = false;
};

// A new run's id: 128 random bits as 32 hex digits (kept by every run continued from its restart
// files).
std::string new_run_id();

// The run id of a run: the restart file's (its lineage), else a new one (a new run, or an older
// restart file that records none).
std::string lineage_run_id(const std::optional<std::filesystem::path>& restart_file,
                           const RunProgress& resumed);

// Where a run continued from a restart file picks up its outputs: in a directory holding its
// own lineage's outputs (OutputDirectory::continues_outputs), thermo.tsv and trajectory.gsd are
// cut back to the rows and frames the state had written (those after it came from a run
// interrupted later: a continued run leaves the files as one uninterrupted run would), and the
// next row is measured from the last kept one; elsewhere (no outputs there) they start afresh.
struct OutputContinuation {
  bool same_directory = false;  // the lineage's outputs are continued
  std::optional<std::uint64_t> thermo_rows, trajectory_frames;
};
OutputContinuation output_continuation(bool continues_outputs, const RunProgress& resumed);

}  // namespace kairos

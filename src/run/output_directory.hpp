// The output directory of a run, claimed for it: created if missing, locked against every other
// run for as long as this one lasts (flock on OUTDIR/.kairos.lock: two runs writing one
// directory would overwrite each other's files), and never holding another run's outputs
// unless the user asks to overwrite them.
#pragma once

#include <filesystem>

namespace kairos {

class OutputDirectory {
 public:
  // `continuing`: a restart (--restart), which may append to the outputs found there.
  // `overwrite`: a new run may replace the outputs of an earlier one (they are removed first).
  // InputError naming the directory if it cannot be created, is in use by another run, or
  // holds an earlier run's outputs.
  OutputDirectory(const std::filesystem::path& dir, bool continuing, bool overwrite);
  ~OutputDirectory();
  OutputDirectory(OutputDirectory&& other) noexcept;
  OutputDirectory& operator=(OutputDirectory&&) = delete;
  OutputDirectory(const OutputDirectory&) = delete;
  OutputDirectory& operator=(const OutputDirectory&) = delete;

  const std::filesystem::path& path() const { return dir_; }

 private:
  std::filesystem::path dir_;
  int lock_fd_ = -1;
};

}  // namespace kairos

// The outputs of a run whose writing failed (a full disk, a size limit): a failed write stops
// the run; the file that failed is not written again (no torn or partial record follows), the
// others still are (the restart file first of all), and the run ends with the error
// (docs/guarantees.md).
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace kairos {

struct OutputFailures {
  std::string error;                // the first failure, then any later ones
  std::vector<std::string> failed;  // the files that failed
  bool failed_file(const std::string& file) const {
    return std::find(failed.begin(), failed.end(), file) != failed.end();
  }
  // Runs `write` for `file` unless that file failed before; false if it failed now or before.
  template <class Write>
  bool attempt(const std::string& file, Write&& write) {
    if (failed_file(file)) return false;
    try {
      write();
      return true;
    } catch (const InputError& e) {
      failed.push_back(file);
      error += (error.empty() ? "" : "; then ") + std::string(e.what());
      return false;
    }
  }
  bool any() const { return !failed.empty(); }
};

}  // namespace kairos

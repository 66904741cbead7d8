// Error types shared by every layer.
//
// InputError is for anything the user can fix (config, files, command line): the CLI prints its
// message on one line and exits non-zero. Internal invariant violations use std::logic_error.
// Interrupted unwinds a setup that a signal or the wall-time limit stopped (core/stop_flag.hpp);
// it is neither of the two, so that no handler of InputError rewraps it.
#pragma once

#include <stdexcept>
#include <string>

namespace kairos {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Interrupted : public std::runtime_error {
 public:
  enum class Cause { kStopRequest, kWallTime };  // request_stop() (a signal), or the deadline
  Interrupted(Cause cause, const std::string& what) : std::runtime_error(what), cause_(cause) {}
  Cause cause() const { return cause_; }

 private:
  Cause cause_;
};

}  // namespace kairos

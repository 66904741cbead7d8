// Error types shared by every layer.
//
// InputError is for anything the user can fix (config, files, command line): the CLI prints its
// message on one line and exits non-zero. Internal invariant violations use std::logic_error.
#pragma once

#include <stdexcept>
#include <string>

namespace kairos {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace kairos

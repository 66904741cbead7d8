// The InputError message of make_initial_state, or "" when it does not throw: shared by the
// initial-state tests.
#pragma once

#include <random>
#include <string>

#include "core/error.hpp"
#include "init/initial_state.hpp"
#include "io/config.hpp"

namespace kairos::test_util {

template <int D>
std::string initial_state_error(const SystemConfig& system) {
  std::mt19937_64 rng(1);
  try {
    (void)make_initial_state<D>(system, rng);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace kairos::test_util

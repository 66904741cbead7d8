// What a restart does with a configuration that differs from the one its restart file was
// written under (the file stores that configuration, kairos/run/config).
//
// Each changed key falls into one of four classes (docs/guarantees.md lists them):
//   - resumed: the change keeps every stored prediction valid (contact laws, run lengths,
//     outputs, driving): the run continues bit-identically from the stored scheduler state;
//   - re-predicted: the predictions depend on it (gravity, shear, walls and their motion,
//     potentials, bonds, soft laws, sleeping): the run continues from the restored positions
//     and velocities with every event predicted afresh and the cells rebuilt — "continued with
//     new physics", not bit-identical to a run that had the new physics from the start;
//   - ignored: the keys that generate a state (particle number, packing fraction, lattice,
//     seed...) do not apply to a restored one; config.toml records the values that made it;
//   - refused: the particles' own sizes, masses and species stay as stored (InputError naming
//     the key).
// Never a mix: one re-predicted key re-predicts everything. A key unknown to these rules is
// re-predicted (the safe side).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "io/config.hpp"

namespace kairos {

struct RestartPlan {
  bool repredict = false;            // some re-predicted key changed (or no stored config)
  std::vector<std::string> changed;  // changed keys that are re-predicted, dotted
  std::vector<std::string> resumed;  // changed keys that keep the predictions valid
  std::vector<std::string> ignored;  // generating keys whose new values are not used
  bool stored_config = false;        // the restart file held its configuration
  // The field the state was run under (stored_config; D components or empty): the stored
  // positions are at each particle's own time, on parabolas of this field.
  std::vector<double> stored_gravity;
  // The configuration as run: the given one with the stored [system] section (the values
  // that made the state) when the file holds one.
  Config used;
};

// `stored`: the configuration text from the restart file (empty: an older file without it; its
// predictions are then resumed as they are, and describe_restart says that a changed physics
// key cannot be detected). `contacts_in_progress`: the state holds soft contacts in
// progress (a change that would re-predict is then refused: their end was computed under the
// old physics). InputError (naming the file and the key) for a refused change.
// `time`: the state's time.
RestartPlan plan_restart(const Config& now, const std::string& stored, bool contacts_in_progress,
                         double time, const std::string& restart_file);

// The sentence the drivers print to stderr and put into summary.json about a restart whose
// configuration changed (empty when nothing changed).
std::string describe_restart(const RestartPlan& plan, const std::string& restart_file);

}  // namespace kairos

// Granular benchmark cases (bench/README.md, "Granular"): a dilute inelastic gas and a vibrated
// bed, each timed interleaved with the elastic hard-sphere fluid, and a pile settling under
// gravity with sleeping particles, timed per interval of simulated time.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace kairos::bench {

struct GranularPlan {
  std::vector<std::string> cases = {"gas", "bed", "pile"};
  std::vector<int> dims;        // empty: each case's default (gas and bed 3D and 2D, pile 3D)
  std::uint64_t particles = 0;  // 0: each case's default
  double eta = 0.0;             // gas packing fraction (area fraction in 2D); 0: 0.1
  double equilibrate = 20.0;    // elastic collisions per particle before the gas is timed
  double timed = 0.0;           // timed collisions per particle (gas, bed); 0: the defaults
  int repeat = 3;               // interleaved repeats (gas, bed)
  // Every cell crossing rescans all neighbours (EngineOptions::incremental_crossings = false),
  // for comparison with the default.
  bool full_crossing_scans = false;
};

// Throws std::invalid_argument naming the first bad field.
void validate(const GranularPlan& plan);

// One line describing the protocol (for the output's header).
std::string granular_protocol(const GranularPlan& plan);

// Runs the cases in plan order; `emit` receives the output (Markdown) piece by piece, each
// finished table row as soon as it is measured.
void run_granular(const GranularPlan& plan, const std::function<void(const std::string&)>& emit);

}  // namespace kairos::bench

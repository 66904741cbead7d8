// Stepped-potential benchmark cases (bench/README.md, "Stepped potentials"): the square-well
// fluid of the stepped-potentials issue and stepped Lennard-Jones tables of several step counts,
// each timed interleaved with the hard-sphere fluid at the same N, density and temperature.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace kairos::bench {

struct SteppedPlan {
  std::vector<std::string> cases = {"sw", "lj"};
  std::uint64_t particles = 0;                  // 0: 32000
  std::vector<int> lj_steps = {5, 10, 20, 40};  // attractive steps of the Lennard-Jones tables
  double equilibrate = 100.0;  // pair events per particle, velocities rescaled to T every 2
  double timed = 0.0;          // timed events per particle; 0: sw 30, lj 10
  int repeat = 3;              // interleaved repeats
  // Candidate loops to compare (interleaved): "vector" (AVX-512 where the CPU has it, the
  // default) and/or "scalar" (EngineOptions::vector_scan = false).
  std::vector<std::string> scans = {"vector"};
};

// Throws std::invalid_argument naming the first bad field.
void validate(const SteppedPlan& plan);

// One line describing the protocol (for the output's header).
std::string stepped_protocol(const SteppedPlan& plan);

// Runs the cases in plan order; `emit` receives the output (Markdown) piece by piece.
void run_stepped(const SteppedPlan& plan, const std::function<void(const std::string&)>& emit);

}  // namespace kairos::bench

// Soft-sphere benchmark cases (bench/README.md, "Soft spheres"; issue 6): a dilute gas of soft
// spheres simulated by the event-driven engine with the Müller–Pöschel collision map (lookup
// tables) and by Kairos's own time-driven DEM (src/dem) at its default time step t_c/50, both
// timed interleaved in one process with the elastic hard-sphere fluid at the same N and density.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace kairos::bench {

struct SoftPlan {
  // Contact laws: "dashpot" (linear spring-dashpot) and/or "hertz" (viscoelastic Hertz).
  std::vector<std::string> cases = {"dashpot", "hertz"};
  std::uint64_t particles = 0;                           // 0: 32000
  std::vector<double> etas = {0.05, 0.2};                // packing fractions (3D)
  std::vector<double> contact_ratios = {100.0, 1000.0};  // mean free time / contact time
  double restitution = 0.9;   // head-on e (Hertz: at the rms normal impact speed 2 sqrt(T/m))
  double equilibrate = 20.0;  // elastic hard-sphere collisions per particle of the start state
  double timed = 0.0;         // event-driven timed collisions per particle; 0: 4
  long dem_steps = 0;         // DEM timed steps per sample; 0: 2000
  int repeat = 3;             // interleaved repeats
  std::string table_cache;    // empty: a fresh temporary directory (tables built, then removed)
  // Non-empty: also write each case for LAMMPS here (start state, input, Kairos's figures in
  // cases.tsv), for bench/lammps_soft.sh.
  std::string lammps_dir;
  // Every cell crossing rescans all neighbours (EngineOptions::incremental_crossings = false)
  // in the event-driven samples, for comparison with the default.
  bool full_crossing_scans = false;
};

// Throws std::invalid_argument naming the first bad field.
void validate(const SoftPlan& plan);

// One line describing the protocol (for the output's header).
std::string soft_protocol(const SoftPlan& plan);

// Runs the cases (every law at every eta and contact ratio); `emit` receives the output
// (Markdown) piece by piece, each finished table row as soon as it is measured.
void run_soft(const SoftPlan& plan, const std::function<void(const std::string&)>& emit);

}  // namespace kairos::bench

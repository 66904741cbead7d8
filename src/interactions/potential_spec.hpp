// What the user asks for, for one species pair or one bond type: a named potential and its
// parameters (docs/config.md, [[potential]] and [[bond]]), turned into a step table for a pair
// whose hard core is at a given contact distance.
#pragma once

#include <string>
#include <vector>

#include "interactions/step_potential.hpp"

namespace kairos {

struct PotentialSpec {
  // square_well | square_shoulder | steps | lennard_jones | wca | yukawa | morse | tabulated
  // (pair potentials); tether | spring (bonds: the pair can never part beyond the table).
  std::string kind = "square_well";
  // square_well / square_shoulder: range lambda (in units of the contact distance) and depth
  // (well) or height (shoulder).
  double lambda = 1.5;
  double depth = 1.0;
  // steps: boundaries (decreasing; the last is the hard core) and the energy of each shell.
  std::vector<double> boundaries;
  std::vector<double> energies;
  // Continuous potentials: energy and length scales, cut-off (0: the kind's default), shifted
  // to zero at the cut-off. yukawa: eps exp(-kappa (r - sigma)) sigma / r; morse:
  // eps [(1 - exp(-alpha (r - r_min)))^2 - 1]; tabulated: two columns (r, U) from `file`.
  double epsilon = 1.0;
  double sigma = 1.0;
  double cutoff = 0.0;
  bool shifted = true;
  double kappa = 1.0;
  double alpha = 6.0;
  double r_min = 0.0;  // morse: position of the minimum (0: sigma)
  std::string file;
  // Bonds. tether: free between the core and max_length. spring: k (r - length)^2 / 2 between
  // the core and max_length, stepped.
  double max_length = 0.0;
  double stiffness = 0.0;
  double length = 0.0;
  // Stepping of continuous potentials (formulas.md §4.1): number of steps (for ΔU placement:
  // steps on the attractive branch, the repulsive branch continuing in the same ΔU down to the
  // core), placement energy | distance | volume, shell energies midpoint | volume | mid_volume
  // | virial (at `temperature`).
  int steps = 10;
  std::string placement = "energy";
  std::string shell_energy = "volume";
  double temperature = 1.0;

  bool operator==(const PotentialSpec&) const = default;
};

// The step table of the spec for a pair whose hard core is `core` (the sum of the two radii):
// its last boundary is `core`. Throws InputError naming the problem (a table whose core is not
// `core`, a cut-off inside the core, an unknown kind, placement or rule, an unreadable file).
StepTable make_step_table(const PotentialSpec& spec, double core);

// The continuous potential of a spec (empty name for square_well, square_shoulder, steps,
// tether): what `kairos steps` draws next to the table.
ContinuousPotential continuous_potential(const PotentialSpec& spec);

}  // namespace kairos

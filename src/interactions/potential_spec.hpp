// What the user asks for, for one species pair or one bond type: a named potential and its
// parameters (docs/config.md, [[potential]] and [[bond]]), turned into a step table for a pair
// whose hard core is at a given contact distance.
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/choices.hpp"
#include "interactions/step_potential.hpp"

namespace kairos {

// The kinds of potentials, by the names potential[].kind / bond[].kind take (potential_kinds()).
enum class PotentialKind {
  kSquareWell,
  kSquareShoulder,
  kSteps,
  kLennardJones,
  kWca,
  kYukawa,
  kMorse,
  kTabulated,
  kSpringDashpot,
  kTether,  // bonds: the pair can never part beyond the table
  kSpring,
};

// Every kind; the nine of [[potential]] (pair potentials); the two of [[bond]].
const Choices<PotentialKind>& potential_kinds();
const Choices<PotentialKind>& pair_potential_kinds();
const Choices<PotentialKind>& bond_potential_kinds();
// potential[].placement and potential[].shell_energy.
const Choices<StepPlacement>& step_placements();
const Choices<StepEnergyRule>& step_energy_rules();

bool is_bond(PotentialKind kind);        // tether, spring
bool is_continuous(PotentialKind kind);  // stepped from a continuous U(r)
bool uses_epsilon(PotentialKind kind);   // lennard_jones, wca, yukawa, morse

struct PotentialSpec {
  // square_well | square_shoulder | steps | lennard_jones | wca | yukawa | morse | tabulated |
  // spring_dashpot (pair potentials); tether | spring (bonds: the pair can never part beyond
  // the table).
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
  // Stepping of continuous potentials (docs/physics.md#stepping-continuous-potentials): number
  // of steps (for ΔU placement: steps on the attractive branch, the repulsive branch continuing
  // in the same ΔU down to the core), placement energy | distance | volume (names:
  // step_placements()), shell energies midpoint | volume | mid_volume | virial (at
  // `temperature`; step_energy_rules()).
  int steps = 10;
  std::string placement = "energy";
  std::string shell_energy = "volume";
  double temperature = 1.0;
  // spring_dashpot (docs/physics.md#spring-dashpot-by-steps): a repulsive spring (stiffness,
  // from `length` in) in `steps` equal steps with a dashpot per step: damping gamma, or the
  // head-on restitution e of the continuous spring-dashpot (> 0: gamma from the closed form of
  // docs/physics.md#dashpot-head-on for the pair's reduced mass); force_zero: no net attraction
  // while separating (false: the naive dashpot).
  double damping = 0.0;
  double restitution = 0.0;  // 0: not given
  bool force_zero = true;

  bool operator==(const PotentialSpec&) const = default;
};

// The step table of the spec for a pair whose hard core is `core` (the sum of the two radii):
// its last boundary is `core`. Throws InputError naming the problem, prefixed "potential
// <kind>: " ("bond <kind>: " for tether and spring): a table whose core is not `core`, a
// cut-off inside the core, a bad parameter, an unknown kind, placement or rule, an unreadable
// file. What each kind takes (defaults in brackets; lengths absolute, not scaled by the core):
//   square_well, square_shoulder: lambda > 1, depth > 0; boundaries {lambda core, core},
//     energy -depth (well) or +depth (shoulder).
//   steps: boundaries and energies as given; the last boundary must be `core` within 1e-12
//     (relative) and is then set to it exactly.
//   lennard_jones: epsilon, sigma > 0, cutoff [2.5 sigma], shifted.
//   wca: epsilon, sigma > 0; the cut-off is always 2^(1/6) sigma (cutoff must be left 0).
//   yukawa: epsilon != 0 (< 0: attractive), sigma > 0, kappa >= 0, cutoff [3 sigma], shifted.
//   morse: epsilon, alpha > 0, r_min [sigma], cutoff [r_min + 6 / alpha, where U = -0.005 eps].
//   tabulated: file; the cut-off is the file's last r (cutoff must be left 0), shifted.
//   tether (bond): max_length > core; boundaries {max_length, core}, energy {0}, beyond +inf.
//   spring (bond): stiffness > 0, core < length < max_length; the harmonic spring stepped like
//     a continuous potential (its well is at `length`), beyond +inf.
//   spring_dashpot: stiffness > 0, length > core (the centre distance where the contact begins;
//     the pair's contact distance `core` is the hard core inside, which the run must never
//     reach), steps >= 1 shells of equal width from `length` to `core` with the spring's energy
//     at each shell's middle radius (placement and shell_energy do not apply), damping >= 0 or
//     restitution in (0, 1] (not both; restitution needs reduced_mass > 0), force_zero.
// damping, restitution and force_zero belong to spring_dashpot only (an error elsewhere).
// The continuous kinds and spring are stepped by step_potential with `steps` (>= 1),
// `placement` (energy | distance | volume), `shell_energy` (midpoint | volume | mid_volume |
// virial) and `temperature` (> 0, used by the virial rule). The two-argument form is 3D; the
// dimension (2 or 3) matters for the volume placement and the volume, mid_volume and virial
// energies.
// reduced_mass: the pair's m_i m_j / (m_i + m_j), which only spring_dashpot's restitution needs
// (NaN: unknown, an error if it is needed).
StepTable make_step_table(const PotentialSpec& spec, double core);
StepTable make_step_table(const PotentialSpec& spec, double core, int dimension,
                          double reduced_mass = std::numeric_limits<double>::quiet_NaN());

// The continuous potential of a spec, defaults filled in (empty name for square_well,
// square_shoulder, steps, tether): what `kairos steps` draws next to the table. Throws
// InputError like make_step_table for its parameters (those that do not involve the core).
ContinuousPotential continuous_potential(const PotentialSpec& spec);

// The outermost boundary the spec's table will have for a pair of contact distance `core` (its
// cut-off; max_length for tether and spring, `length` for spring_dashpot), without building it:
// what the box and the cells must accommodate. 0 for a steps table without boundaries. Throws
// InputError like continuous_potential for the parameters it needs.
double table_cutoff(const PotentialSpec& spec, double core);

// "energy" | "distance" | "volume", and "midpoint" | "volume" | "mid_volume" | "virial"
// (step_placements(), step_energy_rules()); throw InputError listing the accepted names.
StepPlacement parse_step_placement(const std::string& name);
StepEnergyRule parse_step_energy_rule(const std::string& name);

}  // namespace kairos

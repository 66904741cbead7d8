// Pair potentials made of steps (square wells and shoulders, many-step tables, continuous
// potentials mapped onto steps; docs/physics.md#stepped-potentials), and the event at a step:
// bounce or cross.
//
// A table holds strictly decreasing boundaries r_0 > r_1 > ... > r_K: the energy is `beyond`
// (0, or +inf for a bond) beyond r_0 (the cut-off), energy[k] on the shell r_{k+1} < r < r_k,
// and the particles' hard cores meet at r_K (infinite energy inside). Pure functions: the
// continuous potentials (Lennard-Jones, WCA, Yukawa, Morse, harmonic spring, tabulated), their
// stepping by equal energy, distance or volume with four shell-energy rules in 2D and 3D, B2 of
// tables and potentials, and the text report of `kairos steps`. potential_spec.hpp builds the
// table of a config entry.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace kairos {

struct StepTable {
  std::vector<double> boundary;  // r_0 (cut-off) > r_1 > ... > r_K (hard core)
  std::vector<double> energy;    // energy[k] on (r_{k+1}, r_k); one fewer than boundaries
  // Energy beyond the cut-off: 0 for a pair potential, +inf for a bond (the pair can never
  // separate further than r_0).
  double beyond = 0.0;
  // A dashpot by steps (docs/physics.md#spring-dashpot-by-steps): each crossing of a boundary
  // removes gamma |v_n| dr from the pair's normal kinetic energy, dr the width of the deeper of
  // the two shells and v_n the normal speed before the crossing (dissipative_step_event). 0: no
  // dissipation (the conservative step rule, bit for bit). force_zero: while separating down a
  // step the pair gains max(0, -delta_u - gamma |v_n| dr), never less (no net attraction: the
  // force-zero end of contact); false: the naive dashpot, whose pair may be pulled back.
  double damping = 0.0;
  bool force_zero = true;

  double core() const { return boundary.back(); }
  double cutoff() const { return boundary.front(); }
  // U(r): `beyond` beyond the cut-off, +inf inside the core; on a boundary, the outer shell's
  // value.
  double energy_at(double r) const;
  // Throws InputError naming the first problem (too few boundaries, not decreasing, not
  // positive, energies not finite or of the wrong count, damping negative or not finite).
  void check() const;
};

// A square well (eps > 0) or shoulder (eps < 0 gives a shoulder of height -eps): hard core
// sigma, U = -eps for sigma < r < lambda sigma.
StepTable square_well(double sigma, double lambda, double eps);

// Second virial coefficient B2 = -(1/2) int (exp(-U/kT) - 1) d^d r, exact for the table:
// 3D: -2 pi int (exp(-U/kT) - 1) r^2 dr = (2 pi / 3) [r_K^3 + sum_k (1 - exp(-U_k/kT)) (r_k^3 -
// r_{k+1}^3)]; 2D: -pi int (exp(-U/kT) - 1) r dr = (pi / 2) [r_K^2 + sum_k (...) (r_k^2 -
// r_{k+1}^2)]. +inf for a bond (beyond = +inf: the pair is never found apart). Throws InputError
// unless kT > 0 and dimension is 2 or 3.
double second_virial(const StepTable& table, double kT, int dimension = 3);

// What happens when a pair of reduced mass mu, moving apart or together with normal velocity
// v_n (n from j to i; v_n < 0 approaching), meets a boundary where its energy would change by
// delta_u. Bounce (it cannot climb): the normal velocity reverses. Cross: it changes to
// sgn(v_n) sqrt(v_n^2 - 2 delta_u / mu). The impulse on i along n is returned in the
// cancellation-free form -2 delta_u / (v_n + v_n') for a crossing (docs/physics.md#step-event).
struct StepOutcome {
  bool crosses = false;
  double impulse = 0.0;  // J: v_i += J n / m_i, v_j -= J n / m_j
};
StepOutcome step_event(double mu, double v_n, double delta_u);

// The same step with a dashpot (docs/physics.md#spring-dashpot-by-steps): crossing a boundary
// costs the dashpot work dE = gamma |v_n| width, with v_n the normal velocity before the
// crossing. Approaching (or climbing, delta_u >= 0): the pair crosses if
// (1/2) mu v_n^2 >= delta_u + dE and then loses delta_u + dE, else it bounces (elastically: no
// step is crossed, nothing is dissipated).
// Separating down a step (delta_u < 0): with force_zero it gains max(0, -delta_u - dE) and always
// crosses (the step never pulls it back: no net attraction); without, it is charged
// delta_u + dE like a climb (and may bounce back inwards). `dissipated` = the kinetic energy lost
// beyond delta_u (>= 0). damping = 0 gives step_event's outcome bit for bit.
struct DissipativeStepOutcome {
  bool crosses = false;
  double impulse = 0.0;
  double dissipated = 0.0;
};
DissipativeStepOutcome dissipative_step_event(double mu, double v_n, double delta_u, double damping,
                                              double width, bool force_zero);

// A continuous pair potential to be stepped: U(r) on (core, cutoff], and the shape of U, which
// the equal-energy placement needs:
//   r_min > 0: U falls monotonically to its minimum at r_min and rises from there to the
//              cut-off (a well: Lennard-Jones, Morse, the harmonic spring);
//   r_min = 0: U is monotone on the whole range: purely repulsive if it falls towards the
//              cut-off (WCA, Yukawa with eps > 0), purely attractive if it rises (Yukawa with
//              eps < 0). The direction is read off U(core) and U(cutoff).
// A well whose minimum lies at or inside the core, or at or beyond the cut-off, is monotone on
// (core, cutoff] and is treated as such. U is cut at `cutoff` (its value there need not be 0:
// an unshifted potential jumps to `beyond` there).
struct ContinuousPotential {
  std::string name;
  std::function<double(double)> u;
  double r_min = 0.0;
  double cutoff = 0.0;
  // The energy beyond the cut-off: 0 for a pair potential, +inf for a bond (harmonic spring):
  // copied into the step table.
  double beyond = 0.0;
};

// The factories below throw InputError for a non-positive length or energy scale (where one is
// needed), a cut-off that is not finite and positive, or a bad file.

// Lennard-Jones 4 eps [(s/r)^12 - (s/r)^6], cut at rc, shifted to 0 there if `shifted`.
// r_min = 2^(1/6) sigma.
ContinuousPotential lennard_jones(double eps, double sigma, double rc, bool shifted);

// Weeks-Chandler-Andersen: Lennard-Jones cut at 2^(1/6) sigma and shifted up by eps, so that it
// is purely repulsive and reaches 0 at its cut-off 2^(1/6) sigma (r_min = 0).
ContinuousPotential wca(double eps, double sigma);

// Yukawa (screened Coulomb) eps (sigma / r) exp(-kappa (r - sigma)), cut at rc and shifted to 0
// there if `shifted`. Monotone (r_min = 0): repulsive for eps > 0, attractive for eps < 0 (its
// lowest energy is then at the core). kappa >= 0 (0: unscreened Coulomb, cut).
ContinuousPotential yukawa(double eps, double sigma, double kappa, double rc, bool shifted);

// Morse eps [(1 - exp(-alpha (r - r_min)))^2 - 1]: depth eps at r_min, cut at rc and shifted to 0
// there if `shifted`. alpha > 0 is the inverse width of the well.
ContinuousPotential morse(double eps, double r_min, double alpha, double rc, bool shifted);

// A harmonic bond (k / 2) (r - length)^2 between its core and max_length, never cut: its
// cut-off is max_length and beyond it the energy is +inf (beyond = +inf), so its step table is
// a bond. r_min = length; requires k > 0 and 0 < length < max_length.
ContinuousPotential harmonic_spring(double k, double length, double max_length);

// The repulsive half of a spring, (k / 2) (length - r)^2 for r < length and 0 beyond (cut-off
// `length`, r_min = 0: monotone, repulsive): the elastic part of a linear spring-dashpot contact
// that begins at the centre distance `length` (docs/physics.md#spring-dashpot-by-steps).
// Requires k > 0, length > 0.
ContinuousPotential repulsive_spring(double k, double length);

// A potential read from a text file of two whitespace-separated columns r U, one point per line
// ('#' starts a comment; blank lines are skipped). r must be positive and strictly increasing,
// both columns finite, at least two points. Between points U is the monotone cubic (Fritsch-
// Carlson, "pchip") interpolant, so it never overshoots the data and its minimum is the lowest
// tabulated value, at that grid point (r_min; 0 if the lowest value is the first or the last,
// i.e. a monotone U). The cut-off is the last r; U there must be 0 (within 1e-12 of the largest
// |U|) unless `shifted`, which subtracts it from every value. Below the first r, U is NaN
// (stepping then reports that the core lies outside the table). Throws InputError naming the
// file and the line of the first problem.
ContinuousPotential tabulated(const std::string& file, bool shifted);

enum class StepEnergyRule { kMidpoint, kVolumeAverage, kMidVolume, kVirial };
enum class StepPlacement { kEnergy, kDistance, kVolume };

// A continuous potential mapped onto steps (Thomson, Lue & Bannerman, J. Chem. Phys. 140, 034105
// (2014); docs/physics.md#stepping-continuous-potentials), for a pair whose hard core is `core`
// (core < p.cutoff; U(core) finite). Boundaries by `placement`:
//   kDistance: `steps` shells of equal width from the cut-off to the core;
//   kVolume:   `steps` shells of equal volume (r^d equally spaced; d = dimension, 2 or 3);
//   kEnergy:   boundaries where U crosses equally spaced levels (DynamO's default), the last
//              shell running from the last crossing down to the core:
//     a well (core < r_min < cutoff): dU = (U(cutoff) - U_min) / steps; the levels
//       U(cutoff) - dU, ..., U(cutoff) - (steps - 1) dU on the outer branch, then r_min itself,
//       then U_min + dU, U_min + 2 dU, ... up the inner branch while they lie below U(core).
//       `steps` is the number of shells between r_min and the cut-off; for a shifted potential
//       (U(cutoff) = 0) this is DynamO's dU = |U_min| / steps and the levels -k dU. The inner
//       branch adds as many shells as levels fit below U(core).
//     purely repulsive or purely attractive (monotone): dU = |U(core) - U(cutoff)| / steps and
//       the levels U(cutoff) +- k dU, k = 1..steps-1: exactly `steps` shells.
//     It throws InputError if U is not monotone on each branch (sampled; a tabulated U with two
//       wells: use kDistance or kVolume) or if more than kMaxShells shells would be needed.
// Shell energies by `rule` (docs/physics.md#stepping-continuous-potentials, with r^d and
// r^(d-1) dr in d dimensions): U at the shell's middle radius, its volume average, U at the
// radius halving its volume, or the virial rule exp(-U_k/kT) = <exp(-U/kT)> over the shell
// volume, which keeps the table's B2 at temperature kT equal to the potential's (second_virial
// below). The table's `beyond` is the potential's. Throws InputError (without naming the
// potential: callers add that) for steps < 1, a core outside (0, cutoff), kT <= 0, a dimension
// other than 2 or 3.
inline constexpr int kMaxShells = 100000;
StepTable step_potential(const ContinuousPotential& p, StepPlacement placement, int steps,
                         double core, StepEnergyRule rule, double kT = 1.0, int dimension = 3);

// Equal energy steps as above, but ending at a core *energy* rather than a core distance: the
// hard core is where the inner branch reaches core_energy (the levels go on in steps of dU until
// then), and dU = |U_min| / attractive_steps with the levels -k dU
// (docs/physics.md#stepping-continuous-potentials).
StepTable step_by_energy(const ContinuousPotential& p, int attractive_steps, double core_energy,
                         StepEnergyRule rule, double kT = 1.0, int dimension = 3);

// B2 of the continuous potential with a hard core below `core`, by adaptive quadrature (relative
// accuracy ~1e-12): (2 pi / 3) core^3 - 2 pi int_core^cutoff (exp(-U/kT) - 1) r^2 dr in 3D,
// (pi / 2) core^2 - pi int (exp(-U/kT) - 1) r dr in 2D; U is 0 beyond the cut-off (+inf for a
// bond, whose B2 is +inf). A virial-rule table of the same core has the same B2.
double second_virial(const ContinuousPotential& p, double core, double kT, int dimension = 3);

// What `kairos steps` prints: a few '#' comment lines (the number of shells, core, cut-off,
// pair or bond, the potential's name and B2 at kT of the table and, if `p` is given, of the
// continuous potential with the same core), then a tab-separated block with a header line
//   r_outer  r_inner  U_step  U_continuous
// one row per shell from the cut-off inwards; U_continuous is p's U at the shell's middle radius
// (nan without p). Readable with numpy.genfromtxt(names=True, comments='#') or pandas
// read_csv(sep='\t', comment='#').
std::string step_table_report(const StepTable& table, const ContinuousPotential* p, double kT,
                              int dimension = 3);

// The continuous curve for the plot: a header line "r<TAB>U" then `samples` (>= 2) rows with r
// equally spaced from r_from to r_to (both included).
std::string continuous_curve_tsv(const ContinuousPotential& p, double r_from, double r_to,
                                 int samples = 500);

}  // namespace kairos

// Pair potentials made of steps (square wells and shoulders, many-step tables, continuous
// potentials mapped onto steps; formulas.md §4), and the event at a step: bounce or cross.
//
// A table holds strictly decreasing boundaries r_0 > r_1 > ... > r_K: the energy is 0 beyond
// r_0 (the cut-off), energy[k] on the shell r_{k+1} < r < r_k, and the particles' hard cores
// meet at r_K (infinite energy inside). This is the first part of the stepped-potential issue:
// the tables and the step rule as pure functions, before the engine uses them.
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

  double core() const { return boundary.back(); }
  double cutoff() const { return boundary.front(); }
  // U(r): `beyond` beyond the cut-off, +inf inside the core; on a boundary, the outer shell's value.
  double energy_at(double r) const;
  // Throws InputError naming the first problem (too few boundaries, not decreasing, not
  // positive, energies not finite or of the wrong count).
  void check() const;
};

// A square well (eps > 0) or shoulder (eps < 0 gives a shoulder of height -eps): hard core
// sigma, U = -eps for sigma < r < lambda sigma.
StepTable square_well(double sigma, double lambda, double eps);

// Second virial coefficient B2 = -2 pi int (exp(-U/kT) - 1) r^2 dr (3D), exact for the table:
// (2 pi / 3) [r_K^3 + sum_k (1 - exp(-U_k/kT)) (r_k^3 - r_{k+1}^3)].
double second_virial(const StepTable& table, double kT);

// What happens when a pair of reduced mass mu, moving apart or together with normal velocity
// v_n (n from j to i; v_n < 0 approaching), meets a boundary where its energy would change by
// delta_u. Bounce (it cannot climb): the normal velocity reverses. Cross: it changes to
// sgn(v_n) sqrt(v_n^2 - 2 delta_u / mu). The impulse on i along n is returned in the
// cancellation-free form -2 delta_u / (v_n + v_n') for a crossing (formulas.md §4.2).
struct StepOutcome {
  bool crosses = false;
  double impulse = 0.0;  // J: v_i += J n / m_i, v_j -= J n / m_j
};
StepOutcome step_event(double mu, double v_n, double delta_u);

// A continuous pair potential to be stepped: U(r), and where its minimum lies (0: purely
// repulsive). U must fall monotonically from the core to r_min and rise from r_min to the
// cut-off (or fall, for a purely repulsive one).
struct ContinuousPotential {
  std::string name;
  std::function<double(double)> u;
  double r_min = 0.0;
  double cutoff = 0.0;
};

// Lennard-Jones 4 eps [(s/r)^12 - (s/r)^6], cut at rc, shifted to 0 there if `shifted`.
ContinuousPotential lennard_jones(double eps, double sigma, double rc, bool shifted);

enum class StepEnergyRule { kMidpoint, kVolumeAverage, kMidVolume, kVirial };

// Thomson-Lue-Bannerman mapping with equal energy steps (DynamO's default placement):
// dU = |U_min| / attractive_steps; boundaries where U crosses -dU, -2dU, ... on the attractive
// branch, the minimum itself, then the same levels going up the repulsive branch and on, in
// steps of dU, until the level core_energy: there the hard core. Shell energies by `rule`
// (kVirial keeps each shell's contribution to B2 at temperature kT).
StepTable step_by_energy(const ContinuousPotential& p, int attractive_steps, double core_energy,
                         StepEnergyRule rule, double kT = 1.0);

}  // namespace kairos

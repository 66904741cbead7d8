#include "interactions/step_potential.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "core/error.hpp"

namespace kairos {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The r in [lo, hi] where the monotone f crosses `level` (f(lo) and f(hi) on either side), to
// the last bit by bisection.
double crossing(const std::function<double(double)>& f, double level, double lo, double hi) {
  const bool rising = f(hi) > f(lo);
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    ((f(mid) < level) == rising ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// Adaptive Simpson quadrature of f over [a, b] to an absolute tolerance.
double simpson(const std::function<double(double)>& f, double a, double b, double fa, double fm,
               double fb, double whole, double tol, int depth) {
  const double m = 0.5 * (a + b), lm = 0.5 * (a + m), rm = 0.5 * (m + b);
  const double flm = f(lm), frm = f(rm);
  const double left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
  const double right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
  if (depth <= 0 || std::abs(left + right - whole) <= 15.0 * tol) {
    return left + right + (left + right - whole) / 15.0;
  }
  return simpson(f, a, m, fa, flm, fm, left, 0.5 * tol, depth - 1) +
         simpson(f, m, b, fm, frm, fb, right, 0.5 * tol, depth - 1);
}

double integrate(const std::function<double(double)>& f, double a, double b) {
  const double fa = f(a), fm = f(0.5 * (a + b)), fb = f(b);
  const double whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
  return simpson(f, a, b, fa, fm, fb, whole, 1e-15 * (std::abs(whole) + 1e-300), 60);
}

// The energy of the shell (inner, outer) by `rule`.
double shell_energy(const ContinuousPotential& p, double inner, double outer, StepEnergyRule rule,
                    double kT) {
  const double shell = outer * outer * outer - inner * inner * inner;
  switch (rule) {
    case StepEnergyRule::kMidpoint:
      return p.u(0.5 * (inner + outer));
    case StepEnergyRule::kMidVolume:
      return p.u(std::cbrt(0.5 * (outer * outer * outer + inner * inner * inner)));
    case StepEnergyRule::kVolumeAverage:
      return 3.0 / shell * integrate([&](double r) { return p.u(r) * r * r; }, inner, outer);
    case StepEnergyRule::kVirial: {
      const double boltzmann =
          3.0 / shell *
          integrate([&](double r) { return std::exp(-p.u(r) / kT) * r * r; }, inner, outer);
      return -kT * std::log(boltzmann);
    }
  }
  return 0.0;
}

}  // namespace

double StepTable::energy_at(double r) const {
  if (r > boundary.front()) return beyond;
  for (std::size_t k = 0; k + 1 < boundary.size(); ++k)
    if (r > boundary[k + 1]) return energy[k];
  return kInfinity;
}

void StepTable::check() const {
  if (boundary.size() < 2) throw InputError("a step table needs a cut-off and a core radius");
  if (energy.size() + 1 != boundary.size()) {
    throw InputError(fmt::format("a step table with {} boundaries needs {} energies, got {}",
                                 boundary.size(), boundary.size() - 1, energy.size()));
  }
  for (std::size_t k = 0; k < boundary.size(); ++k) {
    if (!(boundary[k] > 0.0) || !std::isfinite(boundary[k])) {
      throw InputError(fmt::format("step radius {} is not a finite positive number", boundary[k]));
    }
    if (k > 0 && !(boundary[k] < boundary[k - 1])) {
      throw InputError(fmt::format("step radii must decrease from the cut-off inwards ({} then {})",
                                   boundary[k - 1], boundary[k]));
    }
  }
  for (const double u : energy)
    if (!std::isfinite(u)) throw InputError("step energies must be finite");
  if (beyond != 0.0 && beyond != kInfinity)
    throw InputError("the energy beyond a step table's cut-off must be 0 or infinite (a bond)");
}

StepTable square_well(double sigma, double lambda, double eps) {
  StepTable t{{lambda * sigma, sigma}, {-eps}};
  t.check();
  return t;
}

double second_virial(const StepTable& t, double kT) {
  const double core = t.core();
  double sum = core * core * core;
  for (std::size_t k = 0; k < t.energy.size(); ++k) {
    const double a = t.boundary[k], b = t.boundary[k + 1];
    sum += -std::expm1(-t.energy[k] / kT) * (a * a * a - b * b * b);
  }
  return 2.0 * std::numbers::pi / 3.0 * sum;
}

StepOutcome step_event(double mu, double v_n, double delta_u) {
  const double need = 2.0 * delta_u / mu;
  if (v_n * v_n < need) return {false, -2.0 * mu * v_n};  // bounce
  const double v_after = std::copysign(std::sqrt(v_n * v_n - need), v_n);
  return {true, -2.0 * delta_u / (v_n + v_after)};
}

ContinuousPotential lennard_jones(double eps, double sigma, double rc, bool shifted) {
  auto lj = [eps, sigma](double r) {
    const double s6 = std::pow(sigma / r, 6);
    return 4.0 * eps * (s6 * s6 - s6);
  };
  const double shift = shifted ? lj(rc) : 0.0;
  return {shifted ? "lennard-jones (shifted)" : "lennard-jones",
          [lj, shift](double r) { return lj(r) - shift; }, std::pow(2.0, 1.0 / 6.0) * sigma, rc};
}

StepTable step_by_energy(const ContinuousPotential& p, int attractive_steps, double core_energy,
                         StepEnergyRule rule, double kT) {
  if (attractive_steps < 1) throw InputError("step_by_energy: at least one attractive step");
  if (!(p.r_min > 0.0) || !(p.r_min < p.cutoff)) {
    throw InputError("step_by_energy: " + p.name + " needs a minimum inside its cut-off");
  }
  const double u_min = p.u(p.r_min);
  if (!(u_min < 0.0)) throw InputError("step_by_energy: " + p.name + " has no attractive well");
  const double du = -u_min / attractive_steps;
  StepTable t;
  t.boundary.push_back(p.cutoff);
  for (int k = 1; k < attractive_steps; ++k)
    t.boundary.push_back(crossing(p.u, -k * du, p.r_min, p.cutoff));
  t.boundary.push_back(p.r_min);
  // Up the repulsive branch: the same levels, then on in steps of du to the core.
  double lo = 0.5 * p.r_min;
  while (p.u(lo) < core_energy) lo *= 0.5;
  for (int j = 1;; ++j) {
    const double level = std::min(u_min + j * du, core_energy);
    t.boundary.push_back(crossing(p.u, level, lo, p.r_min));
    if (level >= core_energy) break;
  }
  for (std::size_t k = 0; k + 1 < t.boundary.size(); ++k)
    t.energy.push_back(shell_energy(p, t.boundary[k + 1], t.boundary[k], rule, kT));
  t.check();
  return t;
}

}  // namespace kairos

#include "interactions/step_potential.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <utility>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/stop_flag.hpp"
#include "interactions/parameter_domain.hpp"

namespace kairos {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kPi = std::numbers::pi;

void check_dimension(int dimension) {
  if (dimension != 2 && dimension != 3)
    throw InputError(fmt::format("the dimension must be 2 or 3, not {}", dimension));
}

void check_temperature(double kT) {
  if (!kPositiveDomain.contains(kT))
    throw InputError(fmt::format("the temperature kT must be positive and finite, not {}", kT));
}

// r^d for d = 0..3, and the inverse of r^d for d = 2, 3.
double power(double r, int d) {
  return d == 3 ? r * r * r : d == 2 ? r * r : d == 1 ? r : 1.0;
}
double root(double x, int d) {
  return d == 3 ? std::cbrt(x) : std::sqrt(x);
}

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

// Counts the subdivisions of one quadrature to poll the stop flag now and then (and at its
// start): an integrand the tolerance cannot be met for may subdivide up to depth 40 (2^40
// panels), and SIGINT must still end it (the result of a quadrature that finishes is unchanged).
struct QuadratureWork {
  unsigned long panels = 0;
  void count() {
    if ((++panels & 4095u) == 0) throw_if_stop_requested();
  }
};

// Adaptive Simpson quadrature of f over [a, b] to an absolute tolerance.
double simpson(const std::function<double(double)>& f, double a, double b, double fa, double fm,
               double fb, double whole, double tol, int depth, QuadratureWork& work) {
  work.count();
  const double m = 0.5 * (a + b), lm = 0.5 * (a + m), rm = 0.5 * (m + b);
  const double flm = f(lm), frm = f(rm);
  const double left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
  const double right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
  if (depth <= 0 || std::abs(left + right - whole) <= 15.0 * tol) {
    return left + right + (left + right - whole) / 15.0;
  }
  return simpson(f, a, m, fa, flm, fm, left, 0.5 * tol, depth - 1, work) +
         simpson(f, m, b, fm, frm, fb, right, 0.5 * tol, depth - 1, work);
}

// int_a^b f to about 1e-13 of int_a^b |f|: 16 panels, each adaptive, the tolerance set by a
// first estimate of int |f| (so that cancelling parts do not make it unreachable).
double integrate(const std::function<double(double)>& f, double a, double b) {
  constexpr int kPanels = 16;
  const double h = (b - a) / kPanels;
  double values[2 * kPanels + 1];
  for (int i = 0; i <= 2 * kPanels; ++i) values[i] = f(a + 0.5 * h * i);
  double scale = 0.0;
  for (int i = 0; i < kPanels; ++i) {
    scale +=
        h / 6.0 *
        (std::abs(values[2 * i]) + 4.0 * std::abs(values[2 * i + 1]) + std::abs(values[2 * i + 2]));
  }
  const double tol = 1e-13 * scale / kPanels + 1e-300;
  double sum = 0.0;
  throw_if_stop_requested();
  QuadratureWork work;
  for (int i = 0; i < kPanels; ++i) {
    const double lo = a + h * i, hi = i + 1 == kPanels ? b : a + h * (i + 1);
    const double fa = values[2 * i], fm = values[2 * i + 1], fb = values[2 * i + 2];
    sum += simpson(f, lo, hi, fa, fm, fb, (hi - lo) / 6.0 * (fa + 4.0 * fm + fb), tol, 40, work);
  }
  return sum;
}

// The energy of the shell (inner, outer) by `rule`, in `d` dimensions.
double shell_energy(const ContinuousPotential& p, double inner, double outer, StepEnergyRule rule,
                    double kT, int d) {
  const double shell = power(outer, d) - power(inner, d);
  switch (rule) {
    case StepEnergyRule::kMidpoint:
      return p.u(0.5 * (inner + outer));
    case StepEnergyRule::kMidVolume:
      return p.u(root(0.5 * (power(outer, d) + power(inner, d)), d));
    case StepEnergyRule::kVolumeAverage:
      return d / shell *
             integrate([&](double r) { return p.u(r) * power(r, d - 1); }, inner, outer);
    case StepEnergyRule::kVirial: {
      const double boltzmann =
          d / shell *
          integrate([&](double r) { return std::exp(-p.u(r) / kT) * power(r, d - 1); }, inner,
                    outer);
      return -kT * std::log(boltzmann);
    }
  }
  return 0.0;
}

// The shell energies of a table whose boundaries are set, then its check.
StepTable finish(const ContinuousPotential& p, StepTable t, StepEnergyRule rule, double kT, int d) {
  for (std::size_t k = 0; k + 1 < t.boundary.size(); ++k)
    t.energy.push_back(shell_energy(p, t.boundary[k + 1], t.boundary[k], rule, kT, d));
  t.beyond = p.beyond;
  t.check();
  return t;
}

// Throws unless U is monotone (non-increasing if `falling`, else non-decreasing) on [lo, hi],
// sampled at 4096 points, to a tolerance of 1e-12 of its range.
void check_monotone(const ContinuousPotential& p, double lo, double hi, bool falling) {
  constexpr int kSamples = 4096;
  const double range = std::abs(p.u(hi) - p.u(lo)) + 1e-300;
  double previous = p.u(lo);
  for (int i = 1; i <= kSamples; ++i) {
    const double r = i == kSamples ? hi : lo + (hi - lo) * i / kSamples;
    const double u = p.u(r);
    if (falling ? u > previous + 1e-12 * range : u < previous - 1e-12 * range) {
      throw InputError(fmt::format(
          "the energy placement needs U to {} between r = {} and {}, but it {} near r = {}; use "
          "the distance or volume placement",
          falling ? "fall" : "rise", lo, hi, falling ? "rises" : "falls", r));
    }
    previous = u;
  }
}

// Boundaries where U crosses the levels, on a monotone branch from `outer` (exclusive) inwards
// to `inner` (exclusive); levels in order, each strictly between U(outer) and U(inner).
void push_crossings(StepTable& t, const ContinuousPotential& p, const std::vector<double>& levels,
                    double inner, double outer) {
  for (std::size_t k = 0; k < levels.size(); ++k) {
    if ((k & 255u) == 255u) throw_if_stop_requested();  // up to kMaxShells bisections
    const double level = levels[k];
    const double r = crossing(p.u, level, inner, outer);
    // A crossing within rounding of the previous boundary or the inner end adds no shell.
    if (r < t.boundary.back() * (1.0 - 1e-12) && r > inner * (1.0 + 1e-12)) t.boundary.push_back(r);
  }
}

void check_shell_count(std::size_t n) {
  if (n > static_cast<std::size_t>(kMaxShells)) {
    throw InputError(fmt::format(
        "the energy placement would need more than {} shells down to the core; use fewer steps, a "
        "larger core, or the distance or volume placement",
        kMaxShells));
  }
}

StepTable energy_boundaries(const ContinuousPotential& p, int steps, double core) {
  const double rc = p.cutoff, u_core = p.u(core), u_cut = p.u(rc);
  StepTable t;
  t.boundary.push_back(rc);
  const bool well = p.r_min > core && p.r_min < rc && p.u(p.r_min) < u_cut && p.u(p.r_min) < u_core;
  if (well) {
    const double u_min = p.u(p.r_min);
    check_monotone(p, p.r_min, rc, false);
    check_monotone(p, core, p.r_min, true);
    const double du = (u_cut - u_min) / steps;
    const double count = std::floor((u_core - u_min) / du);
    check_shell_count(static_cast<std::size_t>(std::min(count, 1e9)) + steps);
    std::vector<double> levels;
    for (int k = 1; k < steps; ++k) levels.push_back(u_cut - k * du);
    push_crossings(t, p, levels, p.r_min, rc);
    t.boundary.push_back(p.r_min);
    levels.clear();
    for (int j = 1; u_min + j * du < u_core; ++j) levels.push_back(u_min + j * du);
    push_crossings(t, p, levels, core, p.r_min);
  } else {
    if (u_core == u_cut) {
      throw InputError(fmt::format(
          "the energy placement needs U to differ between the core ({}) and the cut-off ({})", core,
          rc));
    }
    const bool falling = u_core > u_cut;
    check_monotone(p, core, rc, falling);
    const double du = (u_core - u_cut) / steps;  // signed: levels from the cut-off towards U(core)
    std::vector<double> levels;
    for (int k = 1; k < steps; ++k) levels.push_back(u_cut + k * du);
    push_crossings(t, p, levels, core, rc);
  }
  t.boundary.push_back(core);
  return t;
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
  if (!(damping >= 0.0) || !std::isfinite(damping)) {
    throw InputError(
        fmt::format("a step table's damping must be finite and at least 0, not {}", damping));
  }
}

StepTable square_well(double sigma, double lambda, double eps) {
  StepTable t{{lambda * sigma, sigma}, {-eps}};
  t.check();
  return t;
}

double second_virial(const StepTable& t, double kT, int dimension) {
  check_temperature(kT);
  check_dimension(dimension);
  if (t.beyond == kInfinity) return kInfinity;
  const int d = dimension;
  double sum = power(t.core(), d);
  for (std::size_t k = 0; k < t.energy.size(); ++k)
    sum += -std::expm1(-t.energy[k] / kT) * (power(t.boundary[k], d) - power(t.boundary[k + 1], d));
  return (d == 3 ? 2.0 * kPi / 3.0 : kPi / 2.0) * sum;
}

StepOutcome step_event(double mu, double v_n, double delta_u) {
  const double need = 2.0 * delta_u / mu;
  if (v_n * v_n < need) return {false, -2.0 * mu * v_n};  // bounce
  const double v_after = std::copysign(std::sqrt(v_n * v_n - need), v_n);
  return {true, -2.0 * delta_u / (v_n + v_after)};
}

DissipativeStepOutcome dissipative_step_event(double mu, double v_n, double delta_u, double damping,
                                              double width, bool force_zero) {
  const double work = damping * std::abs(v_n) * width;
  // The kinetic energy the crossing takes: the step plus the dashpot's work, capped at 0 on the
  // way down a step with the force-zero rule.
  double charge = delta_u + work;
  if (force_zero && delta_u < 0.0) charge = std::min(charge, 0.0);
  const StepOutcome out = step_event(mu, v_n, charge);
  return {out.crosses, out.impulse, out.crosses ? charge - delta_u : 0.0};
}

ContinuousPotential lennard_jones(double eps, double sigma, double rc, bool shifted) {
  require_positive(eps, "eps", "lennard_jones: ");
  require_positive(sigma, "sigma", "lennard_jones: ");
  require_positive(rc, "the cut-off", "lennard_jones: ");
  auto lj = [eps, sigma](double r) {
    const double s6 = std::pow(sigma / r, 6);
    return 4.0 * eps * (s6 * s6 - s6);
  };
  const double shift = shifted ? lj(rc) : 0.0;
  return {shifted ? "lennard-jones (shifted)" : "lennard-jones",
          [lj, shift](double r) { return lj(r) - shift; }, std::pow(2.0, 1.0 / 6.0) * sigma, rc,
          0.0};
}

ContinuousPotential wca(double eps, double sigma) {
  require_positive(eps, "eps", "wca: ");
  require_positive(sigma, "sigma", "wca: ");
  auto u = [eps, sigma](double r) {
    const double s6 = std::pow(sigma / r, 6);
    return 4.0 * eps * (s6 * s6 - s6) + eps;
  };
  return {"wca", u, 0.0, std::pow(2.0, 1.0 / 6.0) * sigma, 0.0};
}

ContinuousPotential yukawa(double eps, double sigma, double kappa, double rc, bool shifted) {
  if (!(eps != 0.0) || !std::isfinite(eps))
    throw InputError(fmt::format("yukawa: eps must be finite and non-zero, not {}", eps));
  require_positive(sigma, "sigma", "yukawa: ");
  require_positive(rc, "the cut-off", "yukawa: ");
  if (!(kappa >= 0.0) || !std::isfinite(kappa))
    throw InputError(fmt::format("yukawa: kappa must be finite and >= 0, not {}", kappa));
  auto y = [eps, sigma, kappa](double r) {
    return eps * sigma / r * std::exp(-kappa * (r - sigma));
  };
  const double shift = shifted ? y(rc) : 0.0;
  return {shifted ? "yukawa (shifted)" : "yukawa", [y, shift](double r) { return y(r) - shift; },
          0.0, rc, 0.0};
}

ContinuousPotential morse(double eps, double r_min, double alpha, double rc, bool shifted) {
  require_positive(eps, "eps", "morse: ");
  require_positive(r_min, "r_min", "morse: ");
  require_positive(alpha, "alpha", "morse: ");
  require_positive(rc, "the cut-off", "morse: ");
  auto m = [eps, r_min, alpha](double r) {
    const double e = -std::expm1(-alpha * (r - r_min));  // 1 - exp(-alpha (r - r_min))
    return eps * (e * e - 1.0);
  };
  const double shift = shifted ? m(rc) : 0.0;
  return {shifted ? "morse (shifted)" : "morse", [m, shift](double r) { return m(r) - shift; },
          r_min, rc, 0.0};
}

ContinuousPotential harmonic_spring(double k, double length, double max_length) {
  require_positive(k, "the stiffness k", "spring: ");
  require_positive(length, "length", "spring: ");
  require_positive(max_length, "max_length", "spring: ");
  if (!(length < max_length)) {
    throw InputError(
        fmt::format("spring: length {} must be shorter than max_length {}", length, max_length));
  }
  return {"harmonic spring",
          [k, length](double r) { return 0.5 * k * (r - length) * (r - length); }, length,
          max_length, kInfinity};
}

ContinuousPotential repulsive_spring(double k, double length) {
  require_positive(k, "the stiffness k", "spring_dashpot: ");
  require_positive(length, "length", "spring_dashpot: ");
  return {
      "repulsive spring",
      [k, length](double r) { return r < length ? 0.5 * k * (length - r) * (length - r) : 0.0; },
      0.0, length, 0.0};
}

namespace {

// Monotone piecewise-cubic Hermite interpolation (Fritsch-Carlson slopes with the Fritsch-Butland
// weighted harmonic mean inside, the shape-preserving three-point formula at the ends).
struct Pchip {
  std::vector<double> x, y, d;

  explicit Pchip(std::vector<double> xs, std::vector<double> ys)
      : x(std::move(xs)), y(std::move(ys)), d(x.size(), 0.0) {
    const std::size_t n = x.size();
    std::vector<double> h(n - 1), delta(n - 1);
    for (std::size_t k = 0; k + 1 < n; ++k) {
      h[k] = x[k + 1] - x[k];
      delta[k] = (y[k + 1] - y[k]) / h[k];
    }
    if (n == 2) {
      d[0] = d[1] = delta[0];
      return;
    }
    for (std::size_t k = 1; k + 1 < n; ++k) {
      if (delta[k - 1] * delta[k] <= 0.0) continue;
      const double w1 = 2.0 * h[k] + h[k - 1], w2 = h[k] + 2.0 * h[k - 1];
      d[k] = (w1 + w2) / (w1 / delta[k - 1] + w2 / delta[k]);
    }
    d[0] = end_slope(h[0], h[1], delta[0], delta[1]);
    d[n - 1] = end_slope(h[n - 2], h[n - 3], delta[n - 2], delta[n - 3]);
  }

  static double end_slope(double h0, double h1, double d0, double d1) {
    const double s = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
    if (s * d0 <= 0.0) return 0.0;
    if (d0 * d1 <= 0.0 && std::abs(s) > 3.0 * std::abs(d0)) return 3.0 * d0;
    return s;
  }

  double operator()(double r) const {
    if (!(r >= x.front())) return std::numeric_limits<double>::quiet_NaN();
    if (r >= x.back()) return r == x.back() ? y.back() : 0.0;
    const std::size_t k = std::upper_bound(x.begin(), x.end(), r) - x.begin() - 1;
    const double h = x[k + 1] - x[k], t = (r - x[k]) / h, t2 = t * t, t3 = t2 * t;
    return (2.0 * t3 - 3.0 * t2 + 1.0) * y[k] + (t3 - 2.0 * t2 + t) * h * d[k] +
           (-2.0 * t3 + 3.0 * t2) * y[k + 1] + (t3 - t2) * h * d[k + 1];
  }
};

}  // namespace

ContinuousPotential tabulated(const std::string& file, bool shifted) {
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("cannot read the potential file '{}'", file));
  std::vector<double> rs, us;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const auto where = [&] { return fmt::format("potential file '{}', line {}", file, number); };
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream fields(line);
    std::string a, b, extra;
    if (!(fields >> a)) continue;  // blank or comment only
    if (!(fields >> b) || (fields >> extra)) {
      throw InputError(where() + ": expected two columns, r and U");
    }
    double values[2];
    for (int i = 0; i < 2; ++i) {
      const std::string& text = i == 0 ? a : b;
      const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), values[i]);
      if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(values[i])) {
        throw InputError(fmt::format("{}: '{}' is not a finite number", where(), text));
      }
    }
    if (!(values[0] > 0.0)) throw InputError(fmt::format("{}: r = {} is not positive", where(), a));
    if (!rs.empty() && !(values[0] > rs.back())) {
      throw InputError(
          fmt::format("{}: r = {} does not increase (previous r = {})", where(), a, rs.back()));
    }
    rs.push_back(values[0]);
    us.push_back(values[1]);
  }
  if (rs.size() < 2) {
    throw InputError(fmt::format("potential file '{}' has {} points (r U); it needs at least 2",
                                 file, rs.size()));
  }
  double largest = 0.0;
  for (const double u : us) largest = std::max(largest, std::abs(u));
  if (shifted) {
    const double shift = us.back();
    for (double& u : us) u -= shift;
  } else if (std::abs(us.back()) > 1e-12 * largest) {
    throw InputError(fmt::format(
        "potential file '{}': U at the cut-off (the last r, {}) is {}, not 0; shift it (shifted = "
        "true) or extend the table",
        file, rs.back(), us.back()));
  } else {
    us.back() = 0.0;
  }
  const std::size_t lowest = std::min_element(us.begin(), us.end()) - us.begin();
  const double r_min = lowest == 0 || lowest + 1 == us.size() ? 0.0 : rs[lowest];
  const double cutoff = rs.back();
  return {fmt::format("tabulated ({}){}", file, shifted ? " (shifted)" : ""),
          Pchip(std::move(rs), std::move(us)), r_min, cutoff, 0.0};
}

StepTable step_potential(const ContinuousPotential& p, StepPlacement placement, int steps,
                         double core, StepEnergyRule rule, double kT, int dimension) {
  check_dimension(dimension);
  check_temperature(kT);
  if (steps < 1) throw InputError(fmt::format("steps must be at least 1, not {}", steps));
  if (steps > kMaxShells)
    throw InputError(fmt::format("steps must be at most {}, not {}", kMaxShells, steps));
  if (!(core > 0.0) || !(core < p.cutoff)) {
    throw InputError(
        fmt::format("the hard core {} must be positive and inside the cut-off {}", core, p.cutoff));
  }
  if (!std::isfinite(p.u(core))) {
    throw InputError(fmt::format(
        "U is not finite at the hard core r = {} (a tabulated potential starts at its first r)",
        core));
  }
  const int d = dimension;
  StepTable t;
  switch (placement) {
    case StepPlacement::kEnergy:
      t = energy_boundaries(p, steps, core);
      break;
    case StepPlacement::kDistance:
      for (int k = 0; k < steps; ++k)
        t.boundary.push_back(p.cutoff - (p.cutoff - core) * k / steps);
      t.boundary.push_back(core);
      break;
    case StepPlacement::kVolume: {
      const double outer = power(p.cutoff, d), inner = power(core, d);
      t.boundary.push_back(p.cutoff);
      for (int k = 1; k < steps; ++k)
        t.boundary.push_back(root(outer - (outer - inner) * k / steps, d));
      t.boundary.push_back(core);
      break;
    }
  }
  return finish(p, std::move(t), rule, kT, d);
}

StepTable step_by_energy(const ContinuousPotential& p, int attractive_steps, double core_energy,
                         StepEnergyRule rule, double kT, int dimension) {
  check_dimension(dimension);
  check_temperature(kT);
  if (attractive_steps < 1) throw InputError("step_by_energy: at least one attractive step");
  if (!(p.r_min > 0.0) || !(p.r_min < p.cutoff)) {
    throw InputError("step_by_energy: " + p.name + " needs a minimum inside its cut-off");
  }
  const double u_min = p.u(p.r_min);
  if (!(u_min < 0.0)) throw InputError("step_by_energy: " + p.name + " has no attractive well");
  const double du = -u_min / attractive_steps;
  if (!(core_energy > u_min) || !std::isfinite(core_energy) ||
      (core_energy - u_min) / du > kMaxShells) {
    throw InputError(fmt::format(
        "step_by_energy: the core energy {} must be finite, above the minimum {} and at most {} "
        "steps above it",
        core_energy, u_min, kMaxShells));
  }
  StepTable t;
  t.boundary.push_back(p.cutoff);
  for (int k = 1; k < attractive_steps; ++k)
    t.boundary.push_back(crossing(p.u, -k * du, p.r_min, p.cutoff));
  t.boundary.push_back(p.r_min);
  // Up the repulsive branch: the same levels, then on in steps of du to the core.
  double lo = 0.5 * p.r_min;
  for (int halvings = 0; !(p.u(lo) >= core_energy); ++halvings, lo *= 0.5) {
    if (halvings > 60) {
      throw InputError(
          fmt::format("step_by_energy: {} never reaches the core energy {}", p.name, core_energy));
    }
  }
  for (int j = 1;; ++j) {
    const double level = std::min(u_min + j * du, core_energy);
    t.boundary.push_back(crossing(p.u, level, lo, p.r_min));
    if (level >= core_energy) break;
  }
  return finish(p, std::move(t), rule, kT, dimension);
}

double second_virial(const ContinuousPotential& p, double core, double kT, int dimension) {
  check_dimension(dimension);
  check_temperature(kT);
  if (!(core > 0.0) || !(core < p.cutoff)) {
    throw InputError(
        fmt::format("the hard core {} must be positive and inside the cut-off {}", core, p.cutoff));
  }
  if (!std::isfinite(p.u(core)))
    throw InputError(fmt::format("U is not finite at the hard core r = {}", core));
  if (p.beyond == kInfinity) return kInfinity;
  const int d = dimension;
  const auto mayer = [&](double r) { return -std::expm1(-p.u(r) / kT) * power(r, d - 1); };
  // Split at the minimum, where the integrand peaks.
  double integral = 0.0;
  if (p.r_min > core && p.r_min < p.cutoff) {
    integral = integrate(mayer, core, p.r_min) + integrate(mayer, p.r_min, p.cutoff);
  } else {
    integral = integrate(mayer, core, p.cutoff);
  }
  return (d == 3 ? 2.0 * kPi : kPi) * (power(core, d) / d + integral);
}

std::string step_table_report(const StepTable& t, const ContinuousPotential* p, double kT,
                              int dimension) {
  t.check();
  const bool bond = t.beyond == kInfinity;
  std::string out = fmt::format(
      "# step table: {} shells, hard core {:.10g}, cut-off {:.10g}, {}\n", t.energy.size(),
      t.core(), t.cutoff(),
      bond ? "a bond (infinite energy beyond the cut-off)" : "a pair potential (0 beyond)");
  if (p != nullptr) out += fmt::format("# continuous potential: {}\n", p->name);
  if (bond) {
    out += "# B2: not defined for a bond (the pair never parts)\n";
  } else {
    out += fmt::format("# B2 at kT = {:.10g} ({}D): table {:.10g}", kT, dimension,
                       second_virial(t, kT, dimension));
    if (p != nullptr)
      out += fmt::format(", continuous {:.10g}", second_virial(*p, t.core(), kT, dimension));
    out += " (same hard core)\n";
  }
  out += "r_outer\tr_inner\tU_step\tU_continuous\n";
  for (std::size_t k = 0; k < t.energy.size(); ++k) {
    const double outer = t.boundary[k], inner = t.boundary[k + 1];
    const double u =
        p != nullptr ? p->u(0.5 * (outer + inner)) : std::numeric_limits<double>::quiet_NaN();
    out += fmt::format("{:.12g}\t{:.12g}\t{:.12g}\t{:.12g}\n", outer, inner, t.energy[k], u);
  }
  return out;
}

std::string continuous_curve_tsv(const ContinuousPotential& p, double r_from, double r_to,
                                 int samples) {
  if (samples < 2) throw InputError(fmt::format("at least 2 samples, not {}", samples));
  std::string out = "r\tU\n";
  for (int i = 0; i < samples; ++i) {
    const double r = i + 1 == samples ? r_to : r_from + (r_to - r_from) * i / (samples - 1);
    out += fmt::format("{:.12g}\t{:.12g}\n", r, p.u(r));
  }
  return out;
}

}  // namespace kairos

// The checks io/range_checks.hpp declares (its comments say what each does).
#include "io/range_checks.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/error.hpp"
#include "io/config_choices.hpp"
#include "io/config_keys.hpp"

namespace kairos {

namespace {
constexpr double kPi = std::numbers::pi;
}  // namespace

double RangeScales::speed() const {
  return std::sqrt(kT / mass);
}

double RangeScales::time() const {
  return d_min / speed();
}

double RangeScales::dilute_collision_rate() const {
  const double mean = std::sqrt(kPi) * speed();  // sqrt(pi kT / m)
  return dimension == 3 ? 4.0 * number_density * d_max * d_max * mean
                        : 2.0 * number_density * d_max * mean;
}

double RangeScales::longest_edge() const {
  double longest = 0.0;
  for (const double edge : box) longest = std::max(longest, edge);
  return longest;
}

namespace range_checks {

[[noreturn]] void out_of_range(const std::string& key, double value, double lo, double hi,
                               const std::string& why) {
  throw InputError(fmt::format("{} = {}: out of range, must be in [{:.6g}, {:.6g}] ({})", key,
                               value, lo, hi, why));
}

void within(const std::string& key, double value, double lo, double hi, const std::string& why) {
  if (!(value >= lo && value <= hi)) out_of_range(key, value, lo, hi, why);
}

std::string short_number(double v) {
  const std::string e = fmt::format("{:.0e}", v);  // "1e+09", "1e-09", "5e-01"
  const int exponent = std::stoi(e.substr(e.find('e') + 1));
  if (e.starts_with("1e") && std::stod(e) == v && std::abs(exponent) >= 3)
    return fmt::format("1e{}", exponent);
  return fmt::format("{:g}", v);
}

const Range& declared(const std::string& key) {
  return find_declared(key)->decl->range;
}

void within_declared(const std::string& key, double value, double unit,
                     const std::string& unit_text, const std::string& also) {
  const Range& r = declared(key);
  const std::string span =
      r.lo == 0.0 ? fmt::format("up to {} times ", short_number(r.hi))
                  : fmt::format("{} to {} times ", short_number(r.lo), short_number(r.hi));
  within(key, value, r.lo * unit, r.hi * unit, span + unit_text + also);
}

void magnitude_within(const std::string& key, double value, double hi, const std::string& why) {
  if (!(std::abs(value) <= hi)) {
    throw InputError(fmt::format("{} = {}: out of range, its magnitude must be at most {:.6g} ({})",
                                 key, value, hi, why));
  }
}

std::string energy_unit(const RangeScales& s) {
  return fmt::format("kT = {:.6g}, system.temperature", s.kT);
}
std::string speed_unit(const RangeScales& s) {
  return fmt::format("v = sqrt(kT/m) = {:.6g}, the thermal speed of the lightest particles",
                     s.speed());
}
std::string time_unit(const RangeScales& s) {
  return fmt::format(
      "tau = d_min / v = {:.6g}, d_min = {:.6g} the smallest diameter and v = {:.6g} "
      "the thermal speed",
      s.time(), s.d_min, s.speed());
}
std::string length_unit(const RangeScales& s) {
  return fmt::format("d = {:.6g}, the largest diameter", s.d_max);
}

void check_contact(const ContactConfig& c, const std::string& prefix, const RangeScales& s) {
  const double v = s.speed();
  if (restitution_models().at(c.restitution_model) == RestitutionModel::kViscoelastic) {
    // e(v) falls as (v / restitution_speed)^(1/5): far outside the run's speeds the fixed e says
    // nothing about the collisions that happen (every one elastic, or all e = 0).
    within_declared(prefix + ".restitution_speed", c.restitution_speed, v, speed_unit(s));
  }
  for (std::size_t i = 0; i < c.restitution_table.size(); ++i) {
    within(fmt::format("{}.restitution_table[{}][0]", prefix, i), c.restitution_table[i][0], 0.0,
           1e9 * v, "up to 1e9 times " + speed_unit(s));
  }
  within_declared(prefix + ".elastic_below_speed", c.elastic_below_speed, v, speed_unit(s));
}

void length_within_box(const std::string& key, double value, const RangeScales& s) {
  const double longest = s.longest_edge();
  magnitude_within(key, value, 1e6 * longest,
                   fmt::format("1e6 times the longest box edge, {:.6g}", longest));
}

void check_wall(const WallConfig& w, const std::string& prefix, double edge, const RangeScales& s) {
  check_contact(w.contact, prefix, s);
  const double v = s.speed();
  const double fastest = declared(prefix + ".velocity").hi;
  for (std::size_t a = 0; a < w.velocity.size(); ++a) {
    magnitude_within(fmt::format("{}.velocity[{}]", prefix, a), w.velocity[a], fastest * v,
                     short_number(fastest) + " times " + speed_unit(s));
  }
  if (std::isfinite(edge)) {
    // Not half the edge: both walls of a shaken container (a damper) vibrate in phase and may
    // sweep further; walls that meet are an error when it happens. 1e300 broke the positions.
    const double edges = declared(prefix + ".amplitude").hi;
    within(prefix + ".amplitude", w.amplitude, 0.0, edges * edge,
           fmt::format("up to {} box edges along its axis, {:.6g}", short_number(edges), edge));
  }
  const double fastest_vibration = declared(prefix + ".frequency").hi;
  within(prefix + ".frequency", w.frequency, 0.0, fastest_vibration / s.time(),
         "up to " + short_number(fastest_vibration) + " / tau, " + time_unit(s));
  const double peak = 2.0 * kPi * w.frequency * w.amplitude;
  if (!(peak <= 1e9 * v)) {
    throw InputError(fmt::format(
        "{}: the wall's peak speed 2 pi frequency amplitude = {:.6g} exceeds 1e9 times {}; lower "
        "its amplitude or frequency",
        prefix, peak, speed_unit(s)));
  }
}

}  // namespace range_checks
}  // namespace kairos

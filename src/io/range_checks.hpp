// The scales a dimensional key's range is measured in, and the checks of one key against its
// range in those units (run/config_ranges.hpp checks the whole config; a boundary table,
// io/surface_table.hpp, checks its own keys with these). Every error names the key, its value
// and the allowed range in the key's own units.
#pragma once

#include <string>
#include <vector>

#include "io/config_keys.hpp"
#include "io/wall_config.hpp"

namespace kairos {

// The units of a run (run/config_ranges.hpp): the smallest and largest diameter d_min, d_max,
// the smallest mass m, kT = system.temperature, the thermal speed v = sqrt(kT / m), the time
// tau = d_min / v, and the box.
struct RangeScales {
  int dimension = 3;
  double d_min = 1.0, d_max = 1.0;  // smallest and largest diameter
  double mass = 1.0;                // smallest mass
  double kT = 1.0;                  // system.temperature
  std::vector<double> box;          // edges; empty when there is no state (kairos steps)
  double number_density = 0.0;      // N / V; 0 when there is no state

  double speed() const;  // v = sqrt(kT / m)
  double time() const;   // tau = d_min / v
  // The collision rate per particle of a dilute gas at this density and temperature
  // (Enskog's with g(sigma) = 1, largest diameter): a lower bound of the true one.
  double dilute_collision_rate() const;
  double longest_edge() const;  // of the box; 0 without one
};

namespace range_checks {

// "KEY = VALUE: out of range, must be in [LO, HI] (WHY)".
[[noreturn]] void out_of_range(const std::string& key, double value, double lo, double hi,
                               const std::string& why);
void within(const std::string& key, double value, double lo, double hi, const std::string& why);
// A bound as a message writes it: 1e9, 1e-9, 1e3 (powers of ten from 1e3 up or 1e-3 down),
// else as {:g} does (0.5, 10).
std::string short_number(double v);
// The range declared for a key (io/keys/), by its path ("contact.pair[0].tc").
const Range& declared(const std::string& key);
// `key` against its declared range in units of `unit`, whose value and meaning `unit_text`
// gives: "KEY = V: out of range, must be in [LO, HI] (up to 1e9 times UNIT_TEXT)". `also` (e.g.
// ", or -1 for automatic") is added.
void within_declared(const std::string& key, double value, double unit,
                     const std::string& unit_text, const std::string& also = {});
// The same for a magnitude (a signed value, or 0 meaning off).
void magnitude_within(const std::string& key, double value, double hi, const std::string& why);
// A length (a point's coordinate, a radius) within 1e6 times the longest box edge: further,
// a particle's position loses its digits against it.
void length_within_box(const std::string& key, double value, const RangeScales& s);

// How the scales read in a message.
std::string energy_unit(const RangeScales& s);
std::string speed_unit(const RangeScales& s);
std::string time_unit(const RangeScales& s);
std::string length_unit(const RangeScales& s);

// A contact law's keys ([contact], [[contact.pair]], a wall's) at `prefix`.
void check_contact(const ContactConfig& c, const std::string& prefix, const RangeScales& s);
// A wall's contact law and motion ([[boundary.wall]] at a face, or a [[boundary.plane]]): its
// amplitude is measured in box edges along its axis (`edge`: for a plane, the longest edge).
void check_wall(const WallConfig& w, const std::string& prefix, double edge, const RangeScales& s);

}  // namespace range_checks
}  // namespace kairos

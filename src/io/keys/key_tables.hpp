// The key declarations' shared parts (io/config_keys.hpp): the ranges and choice lists the
// tables use, and the groups each table file defines (src/io/keys/*.cpp, one file per part of
// the config). io/config_keys.cpp places the groups into tables.
//
// The groups point at their defaults (a config struct built at start-up): declared_keys() is
// for run time, never for another file's static initialisation.
#pragma once

#include <string_view>
#include <vector>

#include "core/choices.hpp"
#include "interactions/parameter_domain.hpp"
#include "io/config_keys.hpp"

namespace kairos::key_tables {

inline constexpr double kInf = Range::kInf;
inline constexpr double kMaxParticles = 2147483647.0;  // 2^31 - 1: the engine numbers in 31 bits

template <class E>
inline std::vector<std::string_view> names_of(const Choices<E>& choices) {
  std::vector<std::string_view> out;
  for (const ChoiceEntry<E>& e : choices.entries()) out.push_back(e.name);
  return out;
}
template <auto Registry>
std::vector<std::string_view> choices_of(int) {
  return names_of(Registry());
}
template <auto Registry>
std::vector<std::string_view> choices_in(int dimension) {
  return names_of(Registry(dimension));
}

// Ranges.
inline constexpr Range positive{.lo = 0.0, .lo_open = true};
inline constexpr Range non_negative{.lo = 0.0};
inline constexpr Range unit_range{.lo = 1e-9, .hi = 1e9};  // a key that is a unit: near 1
inline constexpr Range fraction{.lo = 0.0, .hi = 1.0};
inline constexpr Range counted{.lo = 1.0, .hi = 100000.0};
constexpr Range up_to(double hi, Scale scale) {
  return {.lo = 0.0, .hi = hi, .scale = scale};
}
constexpr Range between(double lo, double hi, Scale scale) {
  return {.lo = lo, .hi = hi, .scale = scale};
}
// A range that depends on another key (a potential's kind, a soft law's model): checked by the
// reader's rule for it, and by run/config_ranges.cpp for the kinds that use it.
// A physical domain of interactions/parameter_domain.hpp as a key's range.
constexpr Range domain(const ParameterDomain& d) {
  return {.lo = d.lo, .hi = d.hi, .lo_open = d.lo_open, .hi_open = d.hi_open};
}
constexpr Range by_rule(Range r) {
  r.by_rule = true;
  return r;
}

// The groups, by the file that declares them.
extern const KeyGroup kSystemGroup;
extern const KeyGroup kSpeciesGroup;
extern const KeyGroup kContactLawGroup;
extern const KeyGroup kContactGroup;
extern const KeyGroup kBoundaryGroup;
extern const KeyGroup kWallGroup;
extern const KeyGroup kContainerGroup;
extern const KeyGroup kOutletGroup;
extern const KeyGroup kFieldGroup;
extern const KeyGroup kDrivingGroup;
extern const KeyGroup kRunGroup;
extern const KeyGroup kOutputGroup;
extern const KeyGroup kPotentialGroup;
extern const KeyGroup kSpringDashpotGroup;
extern const KeyGroup kSoftLawGroup;
extern const KeyGroup kSoftGroup;
extern const KeyGroup kAnalysisGroup;
extern const KeyGroup kCompressGroup;
extern const KeyGroup kPairSpeciesGroup;
extern const KeyGroup kPotentialSpeciesGroup;
extern const KeyGroup kWallFaceGroup;
extern const KeyGroup kBondTypeGroup;

}  // namespace kairos::key_tables

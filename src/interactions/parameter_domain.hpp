// The physical domains of the contact laws' parameters, each written once. The factories of
// interactions/ check their arguments against them (the library's contract, whoever calls), and
// the configuration's key declarations (io/keys/) take their ranges from them, so that
// the reader rejects a value by its key with the same bounds before any factory sees it
// (docs/architecture.md, "Each key declared once"). The config's other ranges are sanity bounds
// in the run's units (up to 1e9 kT, ...), narrower than these domains, and live only there.
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

namespace kairos {

struct ParameterDomain {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;

  // Finite and within the bounds.
  constexpr bool contains(double x) const {
    if (!(x - x == 0.0)) return false;  // NaN or infinite
    const bool above = lo_open ? x > lo : x >= lo;
    const bool below = hi_open ? x < hi : x <= hi;
    return above && below;
  }
  // How a message says it: "in [0, 1]", "in (-1, 0.5]", "finite and > 0".
  std::string text() const;
};

// Normal coefficient of restitution of a hard contact (0: plastic, 1: elastic).
inline constexpr ParameterDomain kRestitutionDomain{.lo = 0.0, .hi = 1.0};
// That of a soft contact's law, and the viscoelastic model's reference value: a law with e = 0
// has no finite damping (docs/physics.md#soft-spheres).
inline constexpr ParameterDomain kSoftRestitutionDomain{.lo = 0.0, .hi = 1.0, .lo_open = true};
// Tangential coefficient of restitution beta (-1: smooth, 1: perfectly rough).
inline constexpr ParameterDomain kTangentialRestitutionDomain{.lo = -1.0, .hi = 1.0};
// Poisson's ratio of an isotropic elastic solid.
inline constexpr ParameterDomain kPoissonRatioDomain{.lo = -1.0, .hi = 0.5, .lo_open = true};
// Friction coefficients, damping constants.
inline constexpr ParameterDomain kNonNegativeDomain{.lo = 0.0};
// Stiffnesses, lengths, masses, speeds of a law or a potential.
inline constexpr ParameterDomain kPositiveDomain{.lo = 0.0, .lo_open = true};

// InputError "{prefix}{what} must be {domain.text()}, got {x}" unless domain.contains(x).
void require_in(const ParameterDomain& domain, double x, std::string_view what,
                std::string_view prefix = {});
// The rules of one row (speed, e) of a restitution table, given the previous row's speed: speeds
// finite, >= 0 and strictly increasing; e in kRestitutionDomain. `entry` says which of the pair
// is at fault (0 the speed, 1 e), `why` says how; nullopt if the row is fine.
struct TableRowFault {
  std::size_t entry = 0;
  std::string why;
};
std::optional<TableRowFault> restitution_table_row_fault(double speed,
                                                         std::optional<double> previous_speed,
                                                         double e);

// require_in(kPositiveDomain, ...): "{prefix}{what} must be finite and > 0, got {x}".
void require_positive(double x, std::string_view what, std::string_view prefix = {});

}  // namespace kairos

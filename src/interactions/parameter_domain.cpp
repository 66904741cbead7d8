#include "interactions/parameter_domain.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/error.hpp"

namespace kairos {

std::string ParameterDomain::text() const {
  if (std::isinf(hi)) return fmt::format("finite and {} {:g}", lo_open ? ">" : ">=", lo);
  return fmt::format("in {}{:g}, {:g}{}", lo_open ? "(" : "[", lo, hi, hi_open ? ")" : "]");
}

void require_in(const ParameterDomain& domain, double x, std::string_view what,
                std::string_view prefix) {
  if (!domain.contains(x))
    throw InputError(fmt::format("{}{} must be {}, got {}", prefix, what, domain.text(), x));
}

std::optional<TableRowFault> restitution_table_row_fault(double speed,
                                                         std::optional<double> previous_speed,
                                                         double e) {
  if (!kNonNegativeDomain.contains(speed))
    return TableRowFault{
        0, fmt::format("impact speed must be {}, got {}", kNonNegativeDomain.text(), speed)};
  if (previous_speed && !(speed > *previous_speed))
    return TableRowFault{
        0, fmt::format("impact speeds must be strictly increasing, got {} after {}", speed,
                       *previous_speed)};
  if (!kRestitutionDomain.contains(e))
    return TableRowFault{
        1, fmt::format("restitution must be {}, got {}", kRestitutionDomain.text(), e)};
  return std::nullopt;
}

void require_positive(double x, std::string_view what, std::string_view prefix) {
  require_in(kPositiveDomain, x, what, prefix);
}

}  // namespace kairos

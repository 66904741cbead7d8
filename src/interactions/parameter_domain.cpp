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

}  // namespace kairos

// How the parts of summary.json report a value a run defines only sometimes (docs/outputs.md,
// "Summary values mean what they say").
#pragma once

#include <cmath>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "analysis/block_average.hpp"

namespace kairos {

// `value` under `key` of `where` (summary itself or one of its parts), or null and, in
// summary["undefined"][name], the reason (never NaN as a number).
inline void set_or_explain(nlohmann::json& summary, nlohmann::json& where, const std::string& key,
                           double value, std::string reason, const std::string& name) {
  if (reason.empty() && !std::isfinite(value)) reason = "not finite in this run";
  if (reason.empty()) {
    where[key] = value;
    return;
  }
  where[key] = nullptr;
  summary["undefined"][name] = reason;
}

// The same for a sonine coefficient (granular parts): undefined for an inhomogeneous gas.
// Beside a blocked error bar `KEY`: how many effectively independent blocks it had and whether
// it can be trusted (analysis/block_average.hpp), as KEY_blocks and KEY_reliable.
inline void set_error_quality(nlohmann::json& where, const std::string& key,
                              const BlockAverage& b) {
  where[key + "_blocks"] = b.blocks;
  where[key + "_reliable"] = b.reliable;
}

// Why a bulk value is undefined: walls, open faces or a field make the system inhomogeneous;
// fixed grains (docs/physics.md#fixed-grains) too.
inline const char* not_bulk_reason(bool fixed_grains, bool pressure) {
  if (fixed_grains) {
    return pressure ? "fixed grains: their contacts push on the particles as walls do"
                    : "fixed grains: the gas is not homogeneous";
  }
  return pressure ? "walls, open faces or a field: the pressure is not uniform in the box"
                  : "walls, open faces or a field: the gas is not homogeneous";
}

// Why a span's compressibility Z and pressure are undefined ("" when they are defined): not a
// bulk system, no time elapsed over the span (`span` names it: "production time", "time"), or
// every particle at rest. The summary's and Simulation.pressure()'s one rule.
inline std::string pressure_undefined_reason(bool bulk, bool fixed_grains, double elapsed,
                                             double kT, std::string_view span) {
  if (!bulk) return not_bulk_reason(fixed_grains, true);
  if (!(elapsed > 0.0)) return fmt::format("no {} elapsed", span);
  if (!(kT > 0.0)) return "the particles are at rest (kT = 0)";
  return "";
}

inline void set_sonine_a2(nlohmann::json& summary, nlohmann::json& where, double a2, bool bulk,
                          bool fixed_grains = false) {
  set_or_explain(summary, where, "sonine_a2", a2,
                 !bulk                ? not_bulk_reason(fixed_grains, false)
                 : !std::isfinite(a2) ? "every particle at rest"
                                      : "",
                 "granular.sonine_a2");
}

// a2 = d/(d+2) <c^4>/<c^2>^2 - 1 from the sums of c^2 and c^4 over n particles (NaN at rest).
template <int D>
double sonine_a2(double sum_c2, double sum_c4, double n) {
  const double m2 = sum_c2 / n, m4 = sum_c4 / n;
  return m2 > 0.0 ? D / (D + 2.0) * m4 / (m2 * m2) - 1.0 : std::nan("");
}

}  // namespace kairos

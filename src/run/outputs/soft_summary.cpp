#include "run/outputs/soft_summary.hpp"

namespace kairos {

template <int D>
void SoftSummary<D>::summarize(nlohmann::json& j, const RunContext<D>& run) const {
  const EventCounters& c = engine_.counters();
  const std::uint64_t collisions = c.collisions - start_.collisions;
  auto fraction = [&](std::uint64_t k) {
    return collisions > 0 ? static_cast<double>(k) / static_cast<double>(collisions) : 0.0;
  };
  const std::uint64_t a = c.soft_overlap_fallbacks - start_.soft_overlap_fallbacks;
  const std::uint64_t b = c.soft_early_releases - start_.soft_early_releases;
  const std::uint64_t direct = c.soft_direct_maps - start_.soft_direct_maps;
  nlohmann::json s;
  s["collisions"] = run.config().soft.collisions;
  s["defer_releases"] = run.config().soft.defer_releases;
  s["mapped_contacts"] = c.soft_contacts - start_.soft_contacts;
  s["exception_a_overlap_fallbacks"] = a;
  s["exception_b_early_releases"] = b;
  s["exception_a_fraction"] = fraction(a);
  s["exception_b_fraction"] = fraction(b);
  s["direct_maps"] = direct;
  s["direct_map_fraction"] = fraction(direct);
  s["frozen_now"] = engine_.frozen();
  s["contact_energy"] = engine_.potential_energy();
  nlohmann::json tables = nlohmann::json::array();
  for (const SoftTableUse& use : engine_.tables()) {
    nlohmann::json t;
    t["contact"] = use.contact;
    t["nodes"] = use.report.nodes;
    t["min_normal_speed"] = use.spec.min_normal_speed;
    t["max_normal_speed"] = use.spec.max_normal_speed;
    t["max_tangential_ratio"] = use.spec.max_tangential_ratio;
    t["tolerance"] = use.spec.tolerance;
    t["max_error"] = {{"eps_t", use.report.max_error[0]},
                      {"eps_rdot", use.report.max_error[1]},
                      {"eps_phi", use.report.max_error[2]},
                      {"end_overlap", use.report.max_error[3]}};
    t["from_cache"] = use.report.from_cache;
    t["build_seconds"] = use.report.build_seconds;
    t["cache_file"] = use.report.cache_file.string();
    tables.push_back(t);
  }
  s["tables"] = tables;
  j["soft"] = s;
}

template class SoftSummary<2>;
template class SoftSummary<3>;

}  // namespace kairos

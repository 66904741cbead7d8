#include "run/outputs/run_summary.hpp"

#include <cmath>

namespace kairos {

template <int D>
void RunSummary<D>::summarize(nlohmann::json& j, const RunContext<D>& run) const {
  const Integrator<D>& integrator = run.integrator();
  const auto n = integrator.size();
  j["kairos_version"] = KAIROS_VERSION;
  j["dimension"] = D;
  j["particles"] = n;
  j["packing_fraction"] = integrator.particle_volume() / integrator.volume();
  j["number_density"] = static_cast<double>(n) / integrator.volume();
  j["integrator"] = integrator.name();
  j["run_id"] = run.run_id();
  j["provenance"] = to_json(run.provenance());
  j["restarted"] = run.restarted();
  if (const auto& plan = run.plan()) {
    j["restart"] = {{"mode", plan->repredict ? "new_physics" : "resumed"},
                    {"stored_config", plan->stored_config},
                    {"repredicted_keys", plan->changed},
                    {"resumed_keys", plan->resumed},
                    {"ignored_keys", plan->ignored}};
  }
  j["stop_reason"] = run.stop_reason();
  if (!run.error().empty()) j["error"] = run.error();
  const Vec<D> p = integrator.momentum();
  double dp2 = 0.0;
  for (int a = 0; a < D; ++a) dp2 += (p[a] - momentum_start_[a]) * (p[a] - momentum_start_[a]);
  const double scale = integrator.momentum_scale();
  j["momentum_drift"] = scale > 0 ? std::sqrt(dp2) / scale : 0.0;
  j["max_overlap"] = integrator.max_overlap();
}

template class RunSummary<2>;
template class RunSummary<3>;

}  // namespace kairos

#include "run/outputs/structure_factor_output.hpp"

#include <fmt/format.h>

#include "io/atomic_file.hpp"
#include "run/event_adapter.hpp"
#include "run/outputs/summary_values.hpp"

namespace kairos {

template <int D>
std::string structure_factor_unavailable(const Integrator<D>& integrator,
                                         const Configuration<D>& c) {
  for (int a = 0; a < D; ++a) {
    if (!c.periodic[a]) return "walls or open faces: S(k) needs a periodic box";
  }
  if (const EventIntegrator<D>* engine = integrator.as_event(); engine && engine->kind().sheared)
    return "Lees-Edwards shear: the sheared box has no fixed wave vectors";
  return "";
}

template <int D>
void StructureFactorOutput<D>::begin(const RunContext<D>& run) {
  const Integrator<D>& integrator = run.integrator();
  const Configuration<D>& c = snapshot_->at(integrator);
  if (std::string why = structure_factor_unavailable(integrator, c); !why.empty())
    return this->unavailable(std::move(why));
  k_max_ = run.config().analysis.sk_max > 0.0 ? run.config().analysis.sk_max
                                              : automatic_sk_max(*snapshot_);
  sk_.emplace(c.box, k_max_, sk_fit_max(*snapshot_));
}

template <int D>
void StructureFactorOutput<D>::finish(const RunContext<D>& run) {
  const StructureFactor<D>& s = *sk_;
  std::string text = fmt::format(
      "# {} samples; k: the mean |k| of the shell's wave vectors (shells of pi / L_max); S: "
      "<|rho_k|^2> / N over them and the samples, with its standard error (blocking over the "
      "samples); vectors: used of the shell's available (at most {} per shell); S(0) "
      "extrapolated: {:.10g} +- {:.3g}\n",
      s.samples(), StructureFactor<D>::kMaxVectorsPerShell, s.s_zero().mean, s.s_zero().stderr_);
  text += "k\tS\tS_stderr\tvectors\tavailable\n";
  for (const auto& shell : s.shells()) {
    text += fmt::format("{:.10g}\t{:.10g}\t{:.4g}\t{}\t{}\n", shell.k, shell.s.mean,
                        shell.s.stderr_, shell.vectors, shell.available);
  }
  write_text_atomically(run.directory() / name(), text);
}

template <int D>
void StructureFactorOutput<D>::summarize(nlohmann::json& summary, const RunContext<D>& run) const {
  nlohmann::json* part = this->part(summary, "structure_factor", run);
  if (part == nullptr || !sk_) return;
  nlohmann::json& j = *part;
  const StructureFactor<D>& s = *sk_;
  j["k_max"] = k_max_;
  const auto shells = s.shells();
  j["shells"] = shells.size();
  const std::string few = s.samples() < 2 ? "fewer than 2 samples" : "";
  if (shells.empty()) {
    summary["undefined"]["analysis.structure_factor.k_min"] = "no wave vector up to k_max";
    return;
  }
  j["k_min"] = shells[0].k;
  set_or_explain(summary, j, "s_k_min", shells[0].s.mean, "", "analysis.structure_factor.s_k_min");
  set_or_explain(summary, j, "s_k_min_stderr", shells[0].s.stderr_, few,
                 "analysis.structure_factor.s_k_min_stderr");
  set_error_quality(j, "s_k_min_stderr", shells[0].s);
  j["s_zero_method"] = fmt::format(
      "S = a + b k^2 + c k^4 fitted to the shells with k <= {:.6g} (each weighted by its "
      "vectors), a",
      s.fit_max());
  j["s_zero_shells"] = s.fit_shells();
  const std::string no_fit = s.fit_shells() == 0 ? "fewer than 4 shells below the fit's k" : "";
  set_or_explain(summary, j, "s_zero", s.s_zero().mean, no_fit, "analysis.structure_factor.s_zero");
  set_or_explain(summary, j, "s_zero_stderr", s.s_zero().stderr_, no_fit.empty() ? few : no_fit,
                 "analysis.structure_factor.s_zero_stderr");
  if (no_fit.empty()) set_error_quality(j, "s_zero_stderr", s.s_zero());
}

template std::string structure_factor_unavailable<2>(const Integrator<2>&, const Configuration<2>&);
template std::string structure_factor_unavailable<3>(const Integrator<3>&, const Configuration<3>&);
template class StructureFactorOutput<2>;
template class StructureFactorOutput<3>;

}  // namespace kairos

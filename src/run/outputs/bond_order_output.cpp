#include "run/outputs/bond_order_output.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "run/outputs/summary_values.hpp"

namespace kairos {

template <int D>
void check_bond_cutoff(double cutoff, const StructureSnapshot<D>& snapshot,
                       const Configuration<D>& c, const std::string& key) {
  const double reach = cutoff * 2.0 * snapshot.largest_radius();
  for (int a = 0; a < D; ++a) {
    if (c.periodic[a] && !(reach <= 0.5 * c.box[a])) {
      throw InputError(fmt::format(
          "{} = {}: neighbours up to {:.6g} (the cut-off times the largest "
          "contact distance) reach beyond half the periodic box edge {:.6g}; lower it or use a "
          "larger box",
          key, cutoff, reach, c.box[a]));
    }
  }
}

template <int D>
void BondOrderOutput<D>::begin(const RunContext<D>& run) {
  const Configuration<D>& c = snapshot_->at(run.integrator());
  const double cutoff = run.config().analysis.bond_cutoff;
  check_bond_cutoff(cutoff, *snapshot_, c, "analysis.bond_cutoff");
  order_.emplace(cutoff);
}

template <int D>
void BondOrderOutput<D>::finish(const RunContext<D>& run) {
  const BondOrder<D>& b = *order_;
  std::string text = fmt::format(
      "# {} samples; neighbours closer than {} contact distances ({:.4g} per particle); value: "
      "the bin's centre; per order parameter the probability density of its local value over "
      "the particles and samples;",
      b.samples(), b.cutoff(), b.mean_neighbours());
  for (std::size_t ch = 0; ch < b.names().size(); ++ch) {
    text += fmt::format(" global {} = {:.6g} +- {:.3g}", b.names()[ch], b.global(ch).mean,
                        b.global(ch).stderr_);
  }
  text += "\nvalue";
  for (const std::string& name : b.names()) text += "\t" + name;
  text += "\n";
  for (int k = 0; k < BondOrder<D>::kBins; ++k) {
    text += fmt::format("{:.6g}", (k + 0.5) / BondOrder<D>::kBins);
    for (std::size_t ch = 0; ch < b.names().size(); ++ch)
      text += fmt::format("\t{:.10g}", b.density(ch, k));
    text += "\n";
  }
  write_text_atomically(run.directory() / name(), text);
}

template <int D>
void BondOrderOutput<D>::summarize(nlohmann::json& summary, const RunContext<D>& run) const {
  nlohmann::json* part = this->part(summary, "bond_order", run);
  if (part == nullptr || !order_) return;
  nlohmann::json& j = *part;
  const BondOrder<D>& b = *order_;
  j["cutoff"] = b.cutoff();
  j["mean_neighbours"] = b.mean_neighbours();
  const std::string few = b.samples() < 2 ? "fewer than 2 samples" : "";
  for (std::size_t ch = 0; ch < b.names().size(); ++ch) {
    const std::string& n = b.names()[ch];
    const std::string base = "analysis.bond_order." + n;
    const BlockAverage global = b.global(ch), local = b.local_mean(ch);
    const std::string none = global.samples == 0 ? "no particle has a neighbour" : "";
    nlohmann::json entry;
    set_or_explain(summary, entry, "global", global.mean, none, base + ".global");
    set_or_explain(summary, entry, "global_stderr", global.stderr_, none.empty() ? few : none,
                   base + ".global_stderr");
    set_or_explain(summary, entry, "local_mean", local.mean, none, base + ".local_mean");
    set_or_explain(summary, entry, "local_mean_stderr", local.stderr_, none.empty() ? few : none,
                   base + ".local_mean_stderr");
    if (none.empty()) {
      set_error_quality(entry, "global_stderr", global);
      set_error_quality(entry, "local_mean_stderr", local);
    }
    j[n] = entry;
  }
}

template void check_bond_cutoff<2>(double, const StructureSnapshot<2>&, const Configuration<2>&,
                                   const std::string&);
template void check_bond_cutoff<3>(double, const StructureSnapshot<3>&, const Configuration<3>&,
                                   const std::string&);
template class BondOrderOutput<2>;
template class BondOrderOutput<3>;

}  // namespace kairos

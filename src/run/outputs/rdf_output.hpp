// rdf.tsv (analysis.rdf): g(r) per species pair averaged over the production samples
// (analysis/structure.hpp PairCorrelation), and summary.json's `analysis.rdf`: the contact
// values g(σ⁺) with their blocked errors, and for elastic hard spheres in a periodic box the
// compressibility factor they give by the contact theorem beside the one the collision virial
// measured (summary.json's `compressibility`). docs/outputs.md.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "analysis/structure.hpp"
#include "run/outputs/analysis_output.hpp"
#include "run/outputs/structure_snapshot.hpp"
#include "run/outputs/thermo_output.hpp"

namespace kairos {

// g(r)'s species pairs in the snapshot's last read: their names ("A-B", by species_pair_index),
// contact distances (NaN: none), and why there are no contact values ("": there are; soft
// spheres, stepped potentials, or a species whose radii differ).
struct RdfPairs {
  std::vector<std::string> names;
  std::vector<double> contact;
  std::string no_contact;
};
template <int D>
RdfPairs rdf_pairs(const Integrator<D>& integrator, const StructureSnapshot<D>& snapshot);
// analysis.rdf_max_distance = 0: five of the largest diameters, at most half the shortest edge.
template <int D>
double automatic_rdf_distance(const StructureSnapshot<D>& snapshot, const Configuration<D>& c);

template <int D>
class RdfOutput final : public AnalysisOutput<D> {
 public:
  // `thermo`: for the measured Z.
  RdfOutput(std::shared_ptr<StructureSnapshot<D>> snapshot, const ThermoOutput<D>& thermo)
      : snapshot_(std::move(snapshot)), thermo_(thermo) {}
  static constexpr std::array<std::string_view, 1> kFiles{"rdf.tsv"};
  std::string name() const override { return std::string(kFiles[0]); }
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 protected:
  bool enabled(const Config& config) const override { return config.analysis.rdf; }
  void begin(const RunContext<D>& run) override;
  void take(const RunContext<D>& run) override { rdf_->sample(snapshot_->at(run.integrator())); }
  void finish(const RunContext<D>& run) override;
  std::size_t samples() const override { return rdf_ ? rdf_->samples() : 0; }

 private:
  std::shared_ptr<StructureSnapshot<D>> snapshot_;
  const ThermoOutput<D>& thermo_;
  std::optional<PairCorrelation<D>> rdf_;
  std::vector<std::string> pair_names_;  // "A-B", per species pair
  // Why there are no contact values, or no Z from them ("": there are).
  std::string no_contact_, no_theorem_;
};

}  // namespace kairos

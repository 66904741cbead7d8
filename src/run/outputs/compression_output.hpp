// A new run's compression ([compress], docs/outputs.md "Compression"): compress.tsv (one row
// per thermostat interval: time, packing fraction, reduced pressure, kT before the rescaling,
// collisions), packing.gsd (the grown packing, the run's start, in float64: a start for any
// other run), contacts.tsv (its contact network: pairs, gaps, rattlers) and summary.json's
// `compression`. Written when the run opens: the compression happened in its setup.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/particle_system.hpp"
#include "run/compression.hpp"
#include "run/outputs/observer.hpp"

namespace kairos {

// summary.json's `compression` (and its `undefined` entries) from a report: the observer's
// part, and kairos.Simulation's compression().
void summarize_compression(const CompressionReport& report, int dimension, nlohmann::json& summary);

template <int D>
class CompressionOutput final : public Observer<D> {
 public:
  // The report and the packing it left (copied before the run takes the state over).
  CompressionOutput(std::shared_ptr<const CompressionReport> report,
                    std::shared_ptr<const ParticleSystem<D>> packing)
      : report_(std::move(report)), packing_(std::move(packing)) {}
  // The compression's rows, the packing it left, and that packing's contact network.
  static constexpr std::string_view kRowsFile = "compress.tsv";
  static constexpr std::string_view kPackingFile = "packing.gsd";
  static constexpr std::string_view kContactsFile = "contacts.tsv";
  static constexpr std::array<std::string_view, 3> kFiles{kRowsFile, kPackingFile, kContactsFile};
  std::string name() const override { return std::string(kRowsFile); }
  std::vector<std::string> more_files() const override {
    return {std::string(kPackingFile), std::string(kContactsFile)};
  }
  void open(const RunContext<D>& run) override;
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 private:
  std::shared_ptr<const CompressionReport> report_;
  std::shared_ptr<const ParticleSystem<D>> packing_;
};

}  // namespace kairos

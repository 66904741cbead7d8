// What the structure analyses of [analysis] share as observers (outputs/rdf_output.hpp,
// structure_factor_output.hpp, bond_order_output.hpp, velocity_distribution_output.hpp): each
// samples the production only, at every production thermo row (analysis.interval = 0) or every
// analysis.interval (output.interval_unit), averages over its samples, writes its file at the
// end (atomically) and its part of summary.json's `analysis`. A run continued from a restart
// file starts its averages afresh: the files and summary.json cover this invocation's
// production (`analysis.covers` says so); the restart file records nothing of them.
// Disabled (its key false), it does nothing: no trigger, no file, no part of summary.json.
#pragma once

#include <cstddef>
#include <string>

#include <nlohmann/json.hpp>

#include "run/outputs/observer.hpp"

namespace kairos {

template <int D>
class AnalysisOutput : public Observer<D> {
 public:
  double interval(const Config& config, double /*production*/) const override {
    return enabled(config) ? config.analysis.interval : 0.0;
  }
  void open(const RunContext<D>& run) override {
    on_ = enabled(run.config());
    if (on_) begin(run);
  }
  void sample(const RunContext<D>& run) override {
    if (on_ && run.config().analysis.interval == 0.0) take(run);
  }
  void write(const RunContext<D>& run) override {
    if (on_ && run.phase() == "production") take(run);
  }
  void close(const RunContext<D>& run, bool /*stopped*/) override {
    if (on_ && samples() > 0) finish(run);
  }

 protected:
  virtual bool enabled(const Config& config) const = 0;
  // The run begins (only when enabled): set up the accumulator, or say why it cannot run
  // (unavailable()).
  virtual void begin(const RunContext<D>& run) = 0;
  virtual void take(const RunContext<D>& run) = 0;
  // Writes the file (at least one sample).
  virtual void finish(const RunContext<D>& run) = 0;
  virtual std::size_t samples() const = 0;

  bool on() const { return on_; }
  // This analysis cannot run in this run (a box that is not periodic, ...): no samples, and
  // summary.json says why.
  void unavailable(std::string why) {
    on_ = false;
    why_ = std::move(why);
  }
  // Its part summary["analysis"][key] with the samples and what they cover; nullptr when the
  // analysis is disabled.
  nlohmann::json* part(nlohmann::json& summary, const std::string& key,
                       const RunContext<D>& run) const {
    if (!enabled(run.config())) return nullptr;
    nlohmann::json& analysis = summary["analysis"];
    analysis["covers"] = run.restarted()
                             ? "the production of this invocation only (continued from a restart "
                               "file: averages start afresh)"
                             : "the production";
    analysis["interval"] = run.config().analysis.interval;
    nlohmann::json& p = analysis[key];
    p["samples"] = samples();
    if (!why_.empty()) p["unavailable"] = why_;
    return &p;
  }

 private:
  bool on_ = false;
  std::string why_;
};

}  // namespace kairos

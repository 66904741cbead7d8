// summary.json's `soft` part (event engine with [soft]): how the contacts of this invocation
// were carried out (mapped, or one of the two exceptions: Müller and Pöschel, Phys. Rev. E 87,
// 033301 (2013); docs/soft_tables.md), where the maps came from, and the tables used.
#pragma once

#include <string>

#include "run/event_adapter.hpp"
#include "run/outputs/observer.hpp"

namespace kairos {

template <int D>
class SoftSummary final : public Observer<D> {
 public:
  explicit SoftSummary(const EventIntegrator<D>& engine) : engine_(engine) {}
  std::string name() const override { return "summary.json (soft)"; }
  bool writes_file() const override { return false; }
  void open(const RunContext<D>&) override { start_ = engine_.counters(); }
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 private:
  const EventIntegrator<D>& engine_;
  EventCounters start_;
};

}  // namespace kairos

// summary.json's report of the event engine on itself: its queue, what its events were, its
// memory per particle, and the drift of kinetic plus stepped-potential energy over this
// invocation (docs/outputs.md).
#pragma once

#include <cstdint>
#include <string>

#include "run/event_adapter.hpp"
#include "run/outputs/observer.hpp"

namespace kairos {

template <int D>
class EventSummary final : public Observer<D> {
 public:
  explicit EventSummary(const EventIntegrator<D>& engine) : engine_(engine) {}
  std::string name() const override { return "summary.json (event engine)"; }
  bool writes_file() const override { return false; }
  void open(const RunContext<D>&) override;
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

 private:
  const EventIntegrator<D>& engine_;
  std::uint64_t collisions_start_ = 0;
  double kinetic_start_ = 0.0, potential_start_ = 0.0;
};

}  // namespace kairos

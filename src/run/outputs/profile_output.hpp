// profile.tsv (output.profile_axis): slabs across one axis, sampled at every production thermo
// row and written at the end (analysis/profile.hpp; docs/outputs.md). Without a profile axis it
// does nothing (registered all the same: summary.json lists a profile.tsv an earlier run of the
// lineage left in the directory).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "analysis/profile.hpp"
#include "run/outputs/observer.hpp"

namespace kairos {

template <int D>
class ProfileOutput final : public Observer<D> {
 public:
  static constexpr std::array<std::string_view, 1> kFiles{"profile.tsv"};
  std::string name() const override { return std::string(kFiles[0]); }
  void open(const RunContext<D>& run) override;
  void sample(const RunContext<D>& run) override;
  void close(const RunContext<D>& run, bool) override {
    if (profile_) profile_->write(run.directory() / name());
  }

 private:
  std::optional<AxisProfile<D>> profile_;
};

}  // namespace kairos

// trajectory.gsd: a frame at the start and one per trajectory interval, each committed before
// the next starts (io/gsd_file.hpp), and a last frame at the end unless the last one shows the
// present state (docs/outputs.md).
//
// A continued run appends to its lineage's file, cut back to the frames its restart state had
// written; a run with output.trajectory = false still cuts that file back, so that no frame past
// the restart point is left. The restart file records the last kept frame's state (the frame
// mark), so that a continued run with nothing left to do writes no second frame of it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "io/gsd_file.hpp"
#include "run/outputs/observer.hpp"

namespace kairos {

template <int D>
class TrajectoryOutput final : public Observer<D> {
 public:
  std::string name() const override { return "trajectory.gsd"; }
  // Default: 10 frames per production length.
  double interval(const Config& config, double production) const override {
    return config.output.trajectory_interval > 0 ? config.output.trajectory_interval
                                                 : production / 10.0;
  }
  int schedule_slot() const override { return 1; }
  unsigned owed_bit() const override { return writer_ ? RunProgress::kOwedFrame : 0u; }

  void open(const RunContext<D>& run) override;
  void write(const RunContext<D>& run) override {
    if (writer_) write_frame(run, true);
  }
  void close(const RunContext<D>& run, bool stopped) override;
  void record(RunProgress& progress) const override;

 private:
  // kept: as ThermoOutput's rows.
  void write_frame(const RunContext<D>& run, bool kept);

  std::optional<gsd::Writer> writer_;  // output.trajectory = false: none
  std::uint64_t frames_kept_ = 0;      // of the file, as an uninterrupted run writes them
  // output.trajectory = false: the frames of the lineage's file, cut back to the restart point
  // (-1: none).
  std::int64_t frames_not_written_ = -1;
  StateMark last_;  // the last frame's state
  StateMark kept_;  // the last kept frame's state
};

}  // namespace kairos

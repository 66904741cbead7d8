// trajectory.gsd: a frame at the start and one per trajectory interval, each committed before
// the next starts (io/gsd_file.hpp), and a last frame at the end unless the last one shows the
// present state (docs/outputs.md). Its options (output.trajectory_*): the frames of the
// production only (the first at its start), a choice of per-particle fields, float64 chunks,
// and log-spaced frames from each phase's start (run/trigger.hpp, LogSpacing).
//
// A continued run appends to its lineage's file, cut back to the frames its restart state had
// written; a run with output.trajectory = false still cuts that file back, so that no frame past
// the restart point is left. The restart file records the last kept frame's state (the frame
// mark), so that a continued run with nothing left to do writes no second frame of it, and, for
// log-spaced frames, the origin of their sequence (the driver's part).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "io/gsd_file.hpp"
#include "io/gsd_snapshot.hpp"
#include "run/outputs/observer.hpp"

namespace kairos {

template <int D>
class TrajectoryOutput final : public Observer<D> {
 public:
  static constexpr std::array<std::string_view, 1> kFiles{"trajectory.gsd"};
  std::string name() const override { return std::string(kFiles[0]); }
  // Default: 10 frames per production length. Log-spaced: the first lag (given).
  double interval(const Config& config, double production) const override {
    return config.output.trajectory_interval > 0 ? config.output.trajectory_interval
                                                 : production / 10.0;
  }
  OutputSpacing spacing(const Config& config, const std::string& phase) const override;
  int schedule_slot() const override { return 1; }
  unsigned owed_bit() const override { return enabled_ ? RunProgress::kOwedFrame : 0u; }

  void open(const RunContext<D>& run) override;
  // A frame, unless the last one shows the present state (a phase's first frame after the
  // run's first); with output.trajectory_phases = "production" the first creates the file.
  void write(const RunContext<D>& run) override;
  void close(const RunContext<D>& run, bool stopped) override;
  void record(RunProgress& progress) const override;

 private:
  // kept: as ThermoOutput's rows.
  void write_frame(const RunContext<D>& run, bool kept);
  // The file of a new lineage (or a continuation elsewhere), with the present state as frame 0.
  void create(const RunContext<D>& run);

  bool enabled_ = false;               // output.trajectory
  TrajectoryLayout layout_;            // output.trajectory_fields and trajectory_precision
  std::optional<gsd::Writer> writer_;  // none: output.trajectory = false, or not yet created
  std::uint64_t frames_kept_ = 0;      // of the file, as an uninterrupted run writes them
  // output.trajectory = false: the frames of the lineage's file, cut back to the restart point
  // (-1: none).
  std::int64_t frames_not_written_ = -1;
  StateMark last_;  // the last frame's state
  StateMark kept_;  // the last kept frame's state
};

}  // namespace kairos

#include "run/outputs/trajectory_output.hpp"

#include <filesystem>

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/gsd_snapshot.hpp"

namespace kairos {

namespace {

namespace fs = std::filesystem;

// Appending to another system's trajectory would corrupt it for every reader: InputError unless
// `traj` holds n particles in `dimension` D (the run's output directory `dir` named).
void check_same_trajectory(const fs::path& traj, std::size_t n, int dimension,
                           const fs::path& dir) {
  const gsd::Reader r(traj);
  const auto stored_n = r.find(0, "particles/N") ? r.read<std::uint32_t>(0, "particles/N")
                                                 : std::vector<std::uint32_t>{};
  const auto dims = r.find(0, "configuration/dimensions")
                        ? r.read<std::uint8_t>(0, "configuration/dimensions")
                        : std::vector<std::uint8_t>{3};
  if (stored_n.empty() || stored_n[0] != n || dims.empty() || dims[0] != dimension) {
    throw InputError(fmt::format(
        "output.directory '{}' holds a trajectory.gsd of another system ({} particles in {}D, "
        "this run has {} in {}D): write the continued run to another directory (-o)",
        dir.string(), stored_n.empty() ? 0u : stored_n[0], dims.empty() ? 0 : dims[0], n,
        dimension));
  }
}

}  // namespace

template <int D>
void TrajectoryOutput<D>::open(const RunContext<D>& run) {
  const Integrator<D>& integrator = run.integrator();
  const fs::path& dir = run.directory();
  const fs::path traj = dir / name();
  const std::optional<std::uint64_t> keep = run.continuation().trajectory_frames;
  std::error_code ec;
  if (!run.config().output.trajectory) {
    // Cut the lineage's file back to the frames written up to the restart point, so that no
    // frame past it is left (the next continuation with a trajectory appends after them).
    if (!keep || !fs::exists(traj, ec)) return;
    check_same_trajectory(traj, integrator.size(), D, dir);
    gsd::Writer cut = gsd::Writer::open_append(traj, *keep);
    frames_not_written_ = static_cast<std::int64_t>(cut.frame_count());
    cut.close();
    return;
  }
  // Appended to when a restarted run finds its own system's file there, else created with the
  // present state as frame 0.
  bool created = false;
  if (run.restarted() && fs::exists(traj)) {
    check_same_trajectory(traj, integrator.size(), D, dir);
    writer_.emplace(gsd::Writer::open_append(traj, keep.value_or(~std::uint64_t{0})));
  } else {
    writer_.emplace(gsd::Writer::create(traj, "kairos " KAIROS_VERSION));
    append_trajectory_frame(*writer_, integrator.state_blocks());
    created = true;
  }
  frames_kept_ = writer_->frame_count();
  // The state of the last frame kept: this one's, or, continuing the lineage's file, the one
  // the restart file recorded.
  last_.events = integrator.events();
  const RunProgress& resumed = run.resumed();
  if (created && run.restarted()) {
    last_.collisions = integrator.collisions();
    last_.time = integrator.time();
  } else if (!created && run.continuation().same_directory && resumed.has_frame_mark) {
    last_.collisions = resumed.frame_collisions;
    last_.time = resumed.frame_time;
  }
  kept_ = last_;
}

template <int D>
void TrajectoryOutput<D>::write_frame(const RunContext<D>& run, bool kept) {
  const Integrator<D>& integrator = run.integrator();
  append_trajectory_frame(*writer_, integrator.state_blocks());
  last_ = {integrator.events(), integrator.collisions(), integrator.time()};
  if (kept) {
    frames_kept_ = writer_->frame_count();
    kept_ = last_;
  }
}

template <int D>
void TrajectoryOutput<D>::close(const RunContext<D>& run, bool stopped) {
  if (!writer_) return;
  if (!run.integrator().shows_present_state(last_, run.timed())) write_frame(run, !stopped);
  writer_->close();
}

template <int D>
void TrajectoryOutput<D>::record(RunProgress& progress) const {
  progress.trajectory_frames =
      writer_ ? static_cast<std::int64_t>(frames_kept_) : frames_not_written_;
  if (!writer_) return;
  progress.has_frame_mark = true;
  progress.frame_time = kept_.time;
  progress.frame_collisions = kept_.collisions;
}

template class TrajectoryOutput<2>;
template class TrajectoryOutput<3>;

}  // namespace kairos

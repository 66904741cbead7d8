#include "run/outputs/trajectory_output.hpp"

#include <algorithm>
#include <filesystem>

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/config_choices.hpp"

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

bool has_field(const OutputConfig& o, TrajectoryField field) {
  return std::any_of(o.trajectory_fields.begin(), o.trajectory_fields.end(),
                     [&](const std::string& name) { return trajectory_fields().is(name, field); });
}

// output.trajectory_fields and trajectory_precision as a frame's layout; no fields given:
// every field the state has, static ones in frame 0 only.
TrajectoryLayout layout_of(const OutputConfig& o) {
  TrajectoryLayout layout;
  layout.double_precision =
      trajectory_precisions().is(o.trajectory_precision, TrajectoryPrecision::kDouble);
  if (o.trajectory_fields.empty()) return layout;
  layout.velocity = has_field(o, TrajectoryField::kVelocity);
  layout.image = has_field(o, TrajectoryField::kImage);
  layout.angular_velocity = has_field(o, TrajectoryField::kAngularVelocity);
  layout.typeid_every_frame = has_field(o, TrajectoryField::kTypeid);
  layout.diameter_every_frame = has_field(o, TrajectoryField::kDiameter);
  layout.mass_every_frame = has_field(o, TrajectoryField::kMass);
  return layout;
}

// A field listed in output.trajectory_fields that the state does not have: InputError naming
// the key (the reader refuses "image" under the DEM already).
template <int D>
void check_fields_available(const OutputConfig& o, const Integrator<D>& integrator) {
  if (o.trajectory_fields.empty()) return;
  const StateBlocks<D> state = integrator.state_blocks();
  const ParticleSystem<D> one = state.block(0, std::min<std::size_t>(1, state.particles));
  if (has_field(o, TrajectoryField::kImage) && one.image.empty()) {
    throw InputError(
        "output.trajectory_fields: \"image\" is listed, but this run counts no periodic images "
        "(the DEM integrator does not yet)");
  }
  if (has_field(o, TrajectoryField::kAngularVelocity) && one.angular_velocity.empty()) {
    throw InputError(
        "output.trajectory_fields: \"angular_velocity\" is listed, but the particles do not "
        "spin (smooth spheres: rough ones have contact.tangential_restitution < 1 or friction)");
  }
}

// A continued lineage's file keeps one layout: frames of another precision or other fields
// appended to it would leave readers a mixed file (a velocity missing from later frames reads
// as frame 0's). InputError naming the key; the fields are compared when given.
void check_same_layout(const fs::path& traj, const OutputConfig& o, const TrajectoryLayout& layout,
                       const fs::path& dir) {
  const gsd::Reader r(traj);
  const auto position = r.find(0, "particles/position");
  const bool stored_double = position && position->type == gsd::Type::float64;
  const auto refuse = [&](const std::string& what) {
    throw InputError(fmt::format(
        "output.directory '{}': its trajectory.gsd, continued, holds {}; keep the "
        "trajectory's options of the run it continues, or write the continued run to another "
        "directory (-o)",
        dir.string(), what));
  };
  if (stored_double != layout.double_precision) {
    refuse(fmt::format("{} positions but output.trajectory_precision = \"{}\"",
                       stored_double ? "float64" : "float32", o.trajectory_precision));
  }
  if (o.trajectory_fields.empty()) return;
  const struct {
    const char* chunk;
    const char* field;
    bool wanted;
  } fields[] = {{"particles/velocity", "velocity", layout.velocity},
                {"particles/image", "image", layout.image},
                {"log/particles/angular_velocity", "angular_velocity", layout.angular_velocity}};
  for (const auto& f : fields) {
    const bool stored = r.find(0, f.chunk).has_value();
    if (stored == f.wanted) continue;
    refuse(fmt::format("frames {} {} but output.trajectory_fields {} \"{}\"",
                       stored ? "with" : "without", f.chunk, stored ? "leaves out" : "lists",
                       f.field));
  }
}

bool production_only(const Config& config) {
  return trajectory_phases().is(config.output.trajectory_phases, TrajectoryPhases::kProduction);
}

// A continued run that resumes the production (its restart file was written in it).
template <int D>
bool continues_production(const RunContext<D>& run) {
  const RunProgress& resumed = run.resumed();
  return run.restarted() && !(resumed.equilibration_remaining > 0.0) && resumed.schedule_phase != 0;
}

}  // namespace

template <int D>
OutputSpacing TrajectoryOutput<D>::spacing(const Config& config, const std::string& phase) const {
  const OutputConfig& o = config.output;
  const bool production = phase == "production";
  const bool log = trajectory_spacings().is(o.trajectory_spacing, TrajectorySpacing::kLog);
  OutputSpacing s;
  s.in_phase = production || !production_only(config);
  // Log-spaced frames: their origin, at each phase's start; production only: the first frame.
  s.at_start = log || (production && production_only(config));
  if (log) {
    s.per_decade = static_cast<double>(o.trajectory_frames_per_decade);
    s.period = o.trajectory_log_period;
  }
  return s;
}

template <int D>
void TrajectoryOutput<D>::open(const RunContext<D>& run) {
  const Integrator<D>& integrator = run.integrator();
  const OutputConfig& o = run.config().output;
  const fs::path& dir = run.directory();
  const fs::path traj = dir / name();
  const std::optional<std::uint64_t> keep = run.continuation().trajectory_frames;
  enabled_ = o.trajectory;
  layout_ = layout_of(o);
  std::error_code ec;
  if (!enabled_) {
    // Cut the lineage's file back to the frames written up to the restart point, so that no
    // frame past it is left (the next continuation with a trajectory appends after them).
    if (!keep || !fs::exists(traj, ec)) return;
    if (*keep == 0) {  // none yet (production-only frames, restart before the production)
      fs::remove(traj, ec);
      frames_not_written_ = 0;
      return;
    }
    check_same_trajectory(traj, integrator.size(), D, dir);
    gsd::Writer cut = gsd::Writer::open_append(traj, *keep);
    frames_not_written_ = static_cast<std::int64_t>(cut.frame_count());
    cut.close();
    return;
  }
  check_fields_available(o, integrator);
  // Appended to when a restarted run finds its own system's file there (unless it had no frame
  // yet at the restart point), else created with the present state as frame 0, or, with
  // production-only frames, at the production's start.
  if (run.restarted() && fs::exists(traj)) {
    if (keep && *keep == 0) {
      fs::remove(traj, ec);
    } else {
      check_same_trajectory(traj, integrator.size(), D, dir);
      check_same_layout(traj, o, layout_, dir);
      writer_.emplace(gsd::Writer::open_append(traj, keep.value_or(~std::uint64_t{0})));
      frames_kept_ = writer_->frame_count();
      // The state of the last frame kept: the one the restart file recorded (its events only
      // when it is the present state: the DEM compares those).
      const ProgressMark* mark = run.resumed().mark("frame_mark");
      if (run.continuation().same_directory && mark != nullptr) {
        last_.collisions = mark->counts[0];
        last_.time = mark->values[0];
        const bool present =
            last_.collisions == integrator.collisions() && last_.time == integrator.time();
        last_.events = present ? integrator.events() : ~std::uint64_t{0};
      } else {
        last_.events = integrator.events();
      }
      kept_ = last_;
      return;
    }
  }
  if (production_only(run.config()) && !continues_production(run)) return;
  create(run);
}

template <int D>
void TrajectoryOutput<D>::create(const RunContext<D>& run) {
  writer_.emplace(gsd::Writer::create(run.directory() / name(), "kairos " KAIROS_VERSION));
  write_frame(run, true);
}

template <int D>
void TrajectoryOutput<D>::write(const RunContext<D>& run) {
  if (!enabled_) return;
  if (!writer_) {
    create(run);
    return;
  }
  if (run.integrator().shows_present_state(last_, run.timed())) return;
  write_frame(run, true);
}

template <int D>
void TrajectoryOutput<D>::write_frame(const RunContext<D>& run, bool kept) {
  const Integrator<D>& integrator = run.integrator();
  append_trajectory_frame(*writer_, integrator.state_blocks(), layout_);
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
  // No file yet (production-only frames before the production): none kept.
  progress.trajectory_frames = writer_    ? static_cast<std::int64_t>(frames_kept_)
                               : enabled_ ? 0
                                          : frames_not_written_;
  if (!writer_) return;
  progress.marks["frame_mark"] = {{kept_.time}, {kept_.collisions}};
}

template class TrajectoryOutput<2>;
template class TrajectoryOutput<3>;

}  // namespace kairos

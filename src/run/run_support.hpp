// What the two run drivers share (run/run.cpp for the event-driven engine, run/dem_run.cpp for
// the DEM integrator): the start state, the thermo.tsv writer, the output schedule in
// collisions, the stop flag. Internal to src/run.
#pragma once

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "analysis/block_average.hpp"
#include "analysis/thermodynamics.hpp"
#include "core/error.hpp"
#include "core/particle_system.hpp"
#include "core/periodic.hpp"
#include "dem/dem_integrator.hpp"
#include "init/initial_state.hpp"
#include "io/atomic_file.hpp"
#include "io/config.hpp"
#include "io/gsd_file.hpp"
#include "io/gsd_snapshot.hpp"
#include "io/line_file.hpp"
#include "run/output_directory.hpp"
#include "run/restart_plan.hpp"
#include "run/run.hpp"
#include "run/run_progress.hpp"

namespace kairos::run_detail {

namespace fs = std::filesystem;

inline constexpr double kNeverTime = std::numeric_limits<double>::infinity();

// The state a run starts from: the restart file (its progress into `progress`), else
// system.initial_state, else a generated one (run/run.cpp).
template <int D>
ParticleSystem<D> build_start_state(const Config& config,
                                    const std::optional<fs::path>& restart_file,
                                    std::mt19937_64& rng, RunProgress& progress);

// max_overlap() under Lees-Edwards shear: the particles within the largest diameter of the low
// y face are copied above the box as their images (displaced along x by `offset`), in a box
// tall enough that nothing else wraps around along y.
template <int D>
inline double max_overlap_sheared(const Vec<D>& box, std::vector<Vec<D>> x,
                                  std::vector<double> diameter, double offset) {
  const double dmax = *std::max_element(diameter.begin(), diameter.end());
  const std::size_t n = x.size();
  for (std::size_t i = 0; i < n; ++i) {
    x[i][1] = wrap_into_box(x[i][1], box[1]);
    if (x[i][1] >= dmax) continue;
    Vec<D> image = x[i];
    image[0] = wrap_into_box(image[0] + offset, box[0]);
    image[1] += box[1];
    x.push_back(image);
    diameter.push_back(diameter[i]);
  }
  Vec<D> tall = box;
  tall[1] += 3.0 * dmax;
  return max_overlap<D>(tall, x, diameter);
}

// max_overlap of an engine's present positions: no image along bounded axes, Lees-Edwards
// images displaced by the shear's offset. `state`: its export, `diameters` per particle.
template <class Engine, int D>
double current_max_overlap(const Engine& engine, const ParticleSystem<D>& state,
                           const std::vector<double>& diameters) {
  if (engine.environment().sheared()) {
    return max_overlap_sheared<D>(
        state.box, engine.current_positions(), diameters,
        std::fmod(engine.environment().shear_rate * state.box[1] * state.time, state.box[0]));
  }
  return max_overlap<D>(state.box, state.periodic, engine.current_positions(), diameters);
}

// A state continued under new physics may hold pairs that now overlap (a new potential's core,
// new images): InputError (the driver names the keys).
template <class Engine>
void check_no_overlap_after_new_physics(const Engine& engine) {
  const auto state = engine.export_state(/*with_zones=*/false);
  std::vector<double> diameters(state.size());
  for (std::size_t i = 0; i < state.size(); ++i) diameters[i] = 2.0 * state.kinematics[i].radius;
  const double smallest = *std::min_element(diameters.begin(), diameters.end());
  const double overlap = current_max_overlap(engine, state, diameters);
  if (overlap > 1e-12 * smallest) {
    throw InputError(fmt::format(
        "particles overlap by up to {:.6g} under the new physics; start a new run from the "
        "state with system.initial_state instead",
        overlap));
  }
}

// A restart under a configuration that changed (run/restart_plan.hpp): the plan, and, when the
// run re-predicts, the restored state made ready for a fresh prediction: sleepers woken where
// they rest (their rest was decided under the old physics), the stepped potentials' zones
// recomputed from the distances if a potential or bond changed, the DEM's own state dropped.
// InputError for a refused change.
// The field an older restart file's trajectories followed (it does not record its
// configuration): from the particle that flew longest since its last event, comparing its
// stored position now (kairos/position) with its parabola from the local time. Empty: none.
template <int D>
std::vector<double> inferred_field(const ParticleSystem<D>& s, const std::string& path) {
  const gsd::Reader r(path);
  const std::uint64_t f = r.frame_count() - 1;
  if (!r.find(f, "kairos/position")) return {};
  const std::vector<double> now = r.read<double>(f, "kairos/position");
  std::size_t best = s.size();
  double longest = 0.0;
  for (std::size_t i = 0; i < s.size() && now.size() == s.size() * D; ++i) {
    const double dt = s.time - s.kinematics[i].time;
    if (!s.is_asleep(i) && dt > longest) {
      longest = dt;
      best = i;
    }
  }
  if (best == s.size()) return {};
  std::vector<double> g(D);
  const Kinematics<D>& k = s.kinematics[best];
  for (int a = 0; a < D; ++a) {
    const double drift =
        minimum_image(now[best * D + a] - (k.pos[a] + longest * k.vel[a]), s.box[a]);
    g[a] = 2.0 * drift / (longest * longest);
  }
  return g;
}

template <int D>
RestartPlan plan_continuation(const Config& config, ParticleSystem<D>& state,
                              const RunProgress& resumed, const std::string& restart_file) {
  RestartPlan plan =
      plan_restart(config, resumed.config, !state.frozen.empty(), state.time, restart_file);
  if (plan.repredict && !plan.stored_config)
    plan.stored_gravity = inferred_field(state, restart_file);
  if (plan.repredict) {
    // Every particle brought to the present on its old trajectory (the old field's parabola),
    // so that the new physics starts from where the particles are now.
    state.gravity = Vec<D>{};
    for (int a = 0; a < D && a < static_cast<int>(plan.stored_gravity.size()); ++a)
      state.gravity[a] = plan.stored_gravity[a];
    for (std::size_t i = 0; i < state.size(); ++i) {
      const Vec<D> x = state.position_at(i, state.time), v = state.velocity_at(i, state.time);
      state.kinematics[i].pos = x;
      state.kinematics[i].vel = v;  // a sleeper's is zero
      state.kinematics[i].time = state.time;
    }
    state.asleep.clear();
    const bool potentials = std::any_of(
        plan.changed.begin(), plan.changed.end(),
        [](const std::string& k) { return k.starts_with("potential") || k.starts_with("bond"); });
    if (potentials || !plan.stored_config) state.zones.reset();
    state.dem = {};
  }
  return plan;
}

// An InputError from setting up a restored state (its environment, the engine, the overlap
// check) as the drivers report it: naming the restart file and, under new physics, the keys
// that changed.
inline InputError restart_setup_error(const InputError& e, const fs::path& restart_file,
                                      const RestartPlan& plan) {
  if (plan.repredict && plan.stored_config) {
    return InputError(fmt::format("restart file '{}' continued with new physics ({}): {}",
                                  restart_file.string(), fmt::join(plan.changed, ", "), e.what()));
  }
  return InputError("restart file '" + restart_file.string() + "': " + e.what());
}

// The note on stderr about a restart whose configuration changed (once it is set up).
inline void print_restart_note(const RestartPlan& plan, const std::string& restart_file) {
  const std::string note = describe_restart(plan, restart_file);
  if (!note.empty())
    fmt::print(stderr, "kairos: note: restart from '{}': {}\n", restart_file, note);
}

// summary.json's "restart" part: how the restart used the changed configuration.
inline nlohmann::json restart_summary(const RestartPlan& plan) {
  return {{"mode", plan.repredict ? "new_physics" : "resumed"},
          {"stored_config", plan.stored_config},
          {"repredicted_keys", plan.changed},
          {"resumed_keys", plan.resumed},
          {"ignored_keys", plan.ignored}};
}

// Whether SIGINT/SIGTERM asked the run to stop (request_stop()).
bool stop_requested() noexcept;

// run.integrator = "dem" (run/dem_run.cpp).
template <int D>
RunOutcome run_dem(const Config& config, const std::optional<fs::path>& restart_file,
                   const RunOptions& options);

// Appending to another system's trajectory would corrupt it for every reader: InputError unless
// `traj` holds n particles in `dimension` D (the run's output directory `dir` named).
inline void check_same_trajectory(const fs::path& traj, std::size_t n, int dimension,
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

// A restart file continues only under the integrator that wrote it.
inline void check_restart_integrator(const std::optional<fs::path>& restart_file,
                                     const RunProgress& resumed, std::string_view integrator) {
  if (!restart_file || resumed.integrator == integrator) return;
  throw InputError(
      fmt::format("restart file '{}' was written by run.integrator = \"{}\", this run uses \"{}\"; "
                  "continue it with the same integrator, or start a new run from its state with "
                  "system.initial_state",
                  restart_file->string(), resumed.integrator, integrator));
}

// A new run's id: 128 random bits as 32 hex digits (the lineage of its outputs,
// run/output_directory.hpp; kept by every run continued from its restart files).
inline std::string new_run_id() {
  std::random_device device;
  std::string id;
  for (int k = 0; k < 4; ++k) id += fmt::format("{:08x}", static_cast<std::uint32_t>(device()));
  return id;
}

// The run id of a run: the restart file's (its lineage), else a new one (a new run, or an
// older restart file that records none).
inline std::string lineage_run_id(const std::optional<fs::path>& restart_file,
                                  const RunProgress& resumed) {
  return restart_file && !resumed.run_id.empty() ? resumed.run_id : new_run_id();
}

// Claims the output directory (run/output_directory.hpp) and writes the effective
// configuration into it (after a restart: the configuration as run, RestartPlan::used).
// `restart_file`, `restart_run_id`: the file continued and its run id ("" : none recorded).
inline OutputDirectory prepare_output_directory(const Config& config,
                                                const std::optional<fs::path>& restart_file,
                                                const std::string& restart_run_id,
                                                const RunOptions& options) {
  std::optional<RestartLineage> lineage;
  if (restart_file) lineage = RestartLineage{*restart_file, restart_run_id};
  OutputDirectory dir(config.output.directory, lineage, options.overwrite);
  write_text_atomically(dir.path() / "config.toml", to_toml(config));
  return dir;
}

// Where a run continued from a restart file picks up its outputs: in a directory holding its
// own lineage's outputs (OutputDirectory::continues_outputs), thermo.tsv and trajectory.gsd are
// cut back to the rows and frames the state had written (those after it came from a run
// interrupted later: a continued run leaves the files as one uninterrupted run would), and the
// next row is measured from the last kept one; elsewhere (no outputs there) they start afresh.
struct OutputContinuation {
  bool same_directory = false;  // the lineage's outputs are continued
  std::optional<std::uint64_t> thermo_rows, trajectory_frames;
};
inline OutputContinuation output_continuation(bool continues_outputs, const RunProgress& resumed) {
  OutputContinuation c;
  c.same_directory = continues_outputs;
  if (!c.same_directory) return c;
  if (resumed.thermo_rows >= 0) c.thermo_rows = static_cast<std::uint64_t>(resumed.thermo_rows);
  if (resumed.trajectory_frames >= 0)
    c.trajectory_frames = static_cast<std::uint64_t>(resumed.trajectory_frames);
  return c;
}

// trajectory.gsd of the run in `dir`: appended to when a restarted run finds its own system's
// file there (keeping its first `keep_frames` frames when given), else created with
// `first_frame` (a callable giving the state) as frame 0; true then.
template <int D, class FirstFrame>
bool open_trajectory(std::optional<gsd::Writer>& writer, const fs::path& dir, bool restarted,
                     std::size_t n, std::optional<std::uint64_t> keep_frames,
                     FirstFrame&& first_frame) {
  const fs::path traj = dir / "trajectory.gsd";
  if (restarted && fs::exists(traj)) {
    check_same_trajectory(traj, n, D, dir);
    writer.emplace(gsd::Writer::open_append(traj, keep_frames.value_or(~std::uint64_t{0})));
    return false;
  }
  writer.emplace(gsd::Writer::create(traj, "kairos " KAIROS_VERSION));
  append_trajectory_frame(*writer, first_frame());
  return true;
}

// A continued run that writes no trajectory (output.trajectory = false) still cuts its lineage's
// trajectory.gsd in `dir` back to the `keep_frames` frames written up to the restart point, so
// that no frame past it is left (the next continuation with a trajectory appends after them).
// Returns the frames the file then holds, -1 when there is no file or nothing to keep recorded.
template <int D>
std::int64_t cut_back_trajectory(const fs::path& dir, std::size_t n,
                                 std::optional<std::uint64_t> keep_frames) {
  const fs::path traj = dir / "trajectory.gsd";
  std::error_code ec;
  if (!keep_frames || !fs::exists(traj, ec)) return -1;
  check_same_trajectory(traj, n, D, dir);
  gsd::Writer writer = gsd::Writer::open_append(traj, *keep_frames);
  const auto frames = static_cast<std::int64_t>(writer.frame_count());
  writer.close();
  return frames;
}

// The outputs of a run whose writing failed (a full disk, a size limit): a failed write stops
// the run; the file that failed is not written again (no torn or partial record follows), the
// others still are (the restart file first of all), and the run ends with the error.
struct OutputFailures {
  std::string error;                // the first failure, then any later ones
  std::vector<std::string> failed;  // the files that failed
  bool failed_file(const std::string& file) const {
    return std::find(failed.begin(), failed.end(), file) != failed.end();
  }
  // Runs `write` for `file` unless that file failed before; false if it failed now or before.
  template <class Write>
  bool attempt(const std::string& file, Write&& write) {
    if (failed_file(file)) return false;
    try {
      write();
      return true;
    } catch (const InputError& e) {
      failed.push_back(file);
      error += (error.empty() ? "" : "; then ") + std::string(e.what());
      return false;
    }
  }
  bool any() const { return !failed.empty(); }
};

// What summary.json holds alike for both integrators (docs/outputs.md): counts and rates, the
// times, the temperature, Z with its blocked error, the pressure and the mean free time.
struct RunTotals {
  std::uint64_t events = 0;      // this invocation's (DEM: time steps)
  std::uint64_t collisions = 0;  // this invocation's
  std::uint64_t production_collisions = 0;
  double sim_time = 0.0, production_time = 0.0, wall_seconds = 0.0;
  double production_collisions_per_particle = 0.0;
  double temperature = 0.0, kinetic_energy = 0.0, production_temperature = 0.0;
  double compressibility = 0.0;  // the production mean
};

// A quantity a run defines only sometimes: its value, or null and, in summary["undefined"], the
// reason (never NaN as a number: docs/outputs.md).
inline void set_or_explain(nlohmann::json& summary, nlohmann::json& where, const std::string& key,
                           double value, std::string reason, const std::string& name) {
  if (reason.empty() && !std::isfinite(value)) reason = "not finite in this run";
  if (reason.empty()) {
    where[key] = value;
    return;
  }
  where[key] = nullptr;
  summary["undefined"][name] = reason;
}

// bulk: a periodic box without a field, where Z and the pressure are the uniform bulk values.
inline void add_run_totals(nlohmann::json& j, const RunTotals& r, const Thermodynamics& th,
                           bool bulk) {
  const BlockAverage z_blocks = th.compressibility_blocks();
  const double wall = r.wall_seconds;
  j["events"] = r.events;
  j["collisions"] = r.collisions;
  j["sim_time"] = r.sim_time;
  j["production_time"] = r.production_time;
  j["production_collisions_per_particle"] = r.production_collisions_per_particle;
  j["wall_seconds"] = wall;
  j["events_per_second"] = wall > 0 ? static_cast<double>(r.events) / wall : 0.0;
  j["collisions_per_second"] = wall > 0 ? static_cast<double>(r.collisions) / wall : 0.0;
  j["temperature"] = r.temperature;
  j["kinetic_energy"] = r.kinetic_energy;
  std::string why;
  if (!bulk)
    why = "walls, open faces or a field: the pressure is not uniform in the box";
  else if (!(r.production_time > 0.0))
    why = "no production time elapsed";
  else if (!(r.production_temperature > 0.0))
    why = "the particles are at rest (kT = 0)";
  nlohmann::json z = {{"blocks", z_blocks.samples},
                      {"method", "Flyvbjerg-Petersen blocking over thermo rows"}};
  set_or_explain(j, z, "mean", r.compressibility, why, "compressibility");
  set_or_explain(j, z, "stderr", z_blocks.stderr_,
                 !why.empty()           ? why
                 : z_blocks.samples < 2 ? "fewer than 2 production thermo rows"
                                        : "",
                 "compressibility_stderr");
  j["compressibility"] = z;
  set_or_explain(j, j, "pressure", th.pressure(r.compressibility, r.production_temperature), why,
                 "pressure");
  j["production_temperature"] = r.production_temperature;
  const std::string no_collision =
      r.production_collisions == 0 ? "no collision in the production" : "";
  set_or_explain(j, j, "mean_free_time",
                 th.mean_free_time(r.production_time, r.production_collisions), no_collision,
                 "mean_free_time");
  set_or_explain(j, j, "mean_free_time_stderr", th.mean_free_time_blocks().stderr_,
                 !no_collision.empty()                    ? no_collision
                 : th.mean_free_time_blocks().samples < 2 ? "fewer than 2 production thermo rows"
                                                          : "",
                 "mean_free_time_stderr");
}

// The output files in `dir` after the run, summary.json (about to be written) first
// (summary.json's "outputs").
inline nlohmann::json outputs_present(const fs::path& dir) {
  nlohmann::json list = nlohmann::json::array({"summary.json"});
  std::error_code ec;
  for (const char* name :
       {"thermo.tsv", "trajectory.gsd", "restart.gsd", "profile.tsv", "config.toml"})
    if (fs::exists(dir / name, ec)) list.push_back(name);
  return list;
}

inline std::uint64_t peak_rss_bytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<std::uint64_t>(usage.ru_maxrss) * 1024u;
}

class ThermoWriter {
 public:
  static constexpr const char* kHeader =
      "phase\ttime\tevents\tcollisions\tcollisions_per_particle\ttemperature\tpressure\t"
      "compressibility\tkinetic_energy\tmean_free_time\trotational_temperature\t"
      "dissipated_energy\twall_work\tpotential_energy\n";
  // A new file, or (a continued run) the existing one cut to the `keep_rows` rows the
  // continued state had written (all complete rows when not recorded).
  ThermoWriter(const fs::path& path, bool append, std::optional<std::uint64_t> keep_rows)
      : file_(append ? LineFile(path, kHeader, keep_rows) : LineFile::create(path, kHeader)) {}
  // One row per line, each written whole or not at all (io/line_file.hpp): an interrupted run
  // keeps every earlier row, a failed write (InputError) leaves none torn.
  // Granular columns: rotational temperature, and the energy dissipated and the work done by
  // moving walls since the start of the simulation (zero for elastic hard spheres).
  // potential_energy: of the stepped potentials (0 for hard spheres), or the elastic energy of
  // the overlapping soft pairs (DEM).
  struct Granular {
    double rotational_temperature = 0.0, dissipated = 0.0, wall_work = 0.0;
    double potential_energy = 0.0;
  };
  void write(const std::string& phase, const ThermoRow& r, const Granular& g) {
    file_.append(fmt::format(
        "{}\t{:.17g}\t{}\t{}\t{:.10g}\t{:.17g}\t{:.17g}\t{:.17g}\t{:.17g}\t{:.17g}\t{:.17g}\t"
        "{:.17g}\t{:.17g}\t{:.17g}\n",
        phase, r.at.time, r.at.events, r.at.collisions, r.collisions_per_particle, r.temperature,
        r.pressure, r.compressibility, r.kinetic_energy, r.mean_free_time, g.rotational_temperature,
        g.dissipated, g.wall_work, g.potential_energy));
  }
  std::uint64_t rows() const { return file_.rows(); }

 private:
  LineFile file_;
};

// When the periodic outputs of a phase are due, in collisions (not time: the same schedule at
// any density). Intervals of 0 in the config mean: thermo 100 rows and trajectory 10 frames per
// production length; restart files only at the end.
struct OutputSchedule {
  struct Every {
    std::uint64_t step = 0, next = ~0ull;  // step 0: never
    // True (once) when `collisions` has reached the next multiple.
    bool due(std::uint64_t collisions) {
      if (collisions < next) return false;
      next += step;
      return true;
    }
  };
  Every thermo, trajectory, restart;

  OutputSchedule() = default;  // nothing ever due
  template <class ToCollisions>
  OutputSchedule(const OutputConfig& out, double production, std::uint64_t begin,
                 ToCollisions&& collisions_for) {
    auto every = [&](double per_particle) {
      Every e;
      if (per_particle > 0.0) {
        e.step = std::max<std::uint64_t>(1, collisions_for(per_particle));
        e.next = begin + e.step;
      }
      return e;
    };
    thermo = every(out.thermo_interval > 0 ? out.thermo_interval : production / 100.0);
    trajectory = every(out.trajectory_interval > 0 ? out.trajectory_interval : production / 10.0);
    restart = every(out.restart_interval);
  }
};

// A phase's length: collisions per particle, or simulated time (run.time,
// run.equilibration_time).
struct PhaseLength {
  double value = 0.0;
  bool in_time = false;
  // A phase in time resumed from a restart file: its end as recorded (value is then what was
  // left), so that it ends where the interrupted run would have, bit for bit.
  double end = std::numeric_limits<double>::quiet_NaN();
  // The same for a phase in collisions: the collision count it ends at (0: value from now).
  std::uint64_t target = 0;
};

// The equilibration a restart file leaves to do, in the unit it was started in (its recorded end
// time says: time); a config that gives it in the other unit is refused.
inline PhaseLength resumed_equilibration(const RunConfig& r, const RunProgress& resumed,
                                         const std::string& restart_file) {
  const bool in_time = std::isfinite(resumed.equilibration_end_time);
  const bool config_in_time = r.equilibration_time >= 0.0;
  if (resumed.equilibration_remaining > 0.0 && in_time != config_in_time) {
    throw InputError(fmt::format(
        "restart file '{}' has an unfinished equilibration measured in {}, but the config gives "
        "run.{}: continue it with the same unit",
        restart_file, in_time ? "simulated time" : "collisions per particle",
        config_in_time ? "equilibration_time" : "equilibration_collisions_per_particle"));
  }
  return {resumed.equilibration_remaining, in_time, resumed.equilibration_end_time};
}

// Whether the output intervals are in simulated time (the reader resolves the unit; a config
// built in code may leave it "", the production length's unit).
inline bool intervals_in_time(const Config& c) {
  return c.output.interval_unit == "time" || (c.output.interval_unit.empty() && c.run.time > 0.0);
}

inline PhaseLength production_length(const RunConfig& r) {
  return r.time > 0.0 ? PhaseLength{r.time, true} : PhaseLength{r.collisions_per_particle, false};
}
inline PhaseLength equilibration_length(const RunConfig& r) {
  return r.equilibration_time >= 0.0 ? PhaseLength{r.equilibration_time, true}
                                     : PhaseLength{r.equilibration_collisions_per_particle, false};
}

// Whether the run-length keys changed at a restart (then a new length counts from now).
inline bool length_given_anew(const std::optional<RestartPlan>& plan) {
  if (!plan) return false;
  for (const std::string& k : plan->resumed)
    if (k == "run.collisions_per_particle" || k == "run.time") return true;
  return false;
}

// The production of a continued run: an unfinished one (the restart file records its end) is
// completed, as one uninterrupted run would be, unless the config gives the length anew; a
// finished one is extended by the config's length.
inline PhaseLength continued_production(const RunConfig& r, const RunProgress& resumed,
                                        const std::optional<RestartPlan>& plan, double now,
                                        std::uint64_t collisions) {
  PhaseLength length = production_length(r);
  if (length_given_anew(plan)) return length;
  if (length.in_time && std::isfinite(resumed.production_end_time)) {
    length.end = resumed.production_end_time;
    length.value = std::max(0.0, length.end - now);
  } else if (!length.in_time && resumed.production_target > collisions) {
    length.target = resumed.production_target;
  }
  return length;
}

// When the periodic outputs are due with output.interval_unit = "time": at the multiples of
// each interval (k * step, k an integer), not at offsets from the phase's start, so that a
// continued run writes at the times one uninterrupted run would, and a vibrated wall is seen at
// the same phases in every frame. Intervals of 0: as OutputSchedule.
struct TimeSchedule {
  struct Every {
    double step = 0.0, next = std::numeric_limits<double>::infinity();  // step 0: never
    // k * step is not the decimal multiple (3 * 0.1 = 0.30000000000000004): a multiple within
    // this of t counts as t, so that no output follows another (or a phase's end) by 1e-16.
    static double slack(double t) { return 1e-12 * std::abs(t); }
    // The first multiple of step after t (beyond the slack).
    double after(double t) const {
      double k = std::floor(t / step) + 1.0;
      // A step below t's resolution (t / step > 2^53) would never move k: a few tries only.
      for (int tries = 0; tries < 4 && k * step <= t + slack(t); ++tries) k += 1.0;
      return std::max(k * step, std::nextafter(t + slack(t), kInfinity));
    }
    // True (once) when t has reached the next multiple.
    bool due(double t) {
      if (!(t >= next - slack(next))) return false;
      next = after(t);
      return true;
    }
    static constexpr double kInfinity = std::numeric_limits<double>::infinity();
  };
  Every thermo, trajectory, restart;

  TimeSchedule() = default;  // nothing ever due
  TimeSchedule(const OutputConfig& out, double production_time, double begin) {
    auto every = [&](double interval) {
      Every e;
      if (interval > 0.0) {
        e.step = interval;
        e.next = e.after(begin);
      }
      return e;
    };
    thermo = every(out.thermo_interval > 0 ? out.thermo_interval : production_time / 100.0);
    trajectory =
        every(out.trajectory_interval > 0 ? out.trajectory_interval : production_time / 10.0);
    restart = every(out.restart_interval);
  }
  double next() const { return std::min({thermo.next, trajectory.next, restart.next}); }
};

// The DEM's clock against times its steps (dt apart) cannot hit exactly: a time is reached at
// the first step at or after it (round-off aside: time_at(steps) need not hit a multiple of dt).
template <int D>
bool dem_reached(const DemIntegrator<D>& dem, double t) {
  return dem.time() >= t - 1e-9 * dem.dt();
}
// Steps until the first step at or after time t (at least one).
template <int D>
long dem_steps_to(const DemIntegrator<D>& dem, double t) {
  const double steps = std::ceil((t - dem.time()) / dem.dt() - 1e-9);
  return steps < 1.0 ? 1l
         : steps > static_cast<double>(std::numeric_limits<long>::max() / 2)
             ? std::numeric_limits<long>::max() / 2
             : static_cast<long>(steps);
}
// A DEM state's restart file, with the integrator's checkpoint (bit-identical continuation).
template <int D>
void write_dem_restart(const fs::path& path, const DemIntegrator<D>& dem,
                       const std::mt19937_64& rng, const RunProgress& progress) {
  ParticleSystem<D> s = dem.export_state();
  s.dem = dem.checkpoint();
  const std::size_t n = s.size();
  s.events.assign(n, EventSlot{});  // a DEM state has no scheduler: empty event slots, never read
  s.cell.assign(n, 0);
  s.collision_count.resize(n, 0);
  kairos::write_restart_file(path, s, rng, progress);
}

// The ideal-gas estimate of how far and how long a particle flies between collisions, from the
// mean density, the mean diameter and the rms speed (the Boltzmann mean free path
// 1 / (sqrt 2 n pi sigma^2) in 3D, 1 / (2 sqrt 2 n sigma) in 2D: Chapman and Cowling, The
// Mathematical Theory of Non-uniform Gases, 3rd ed. 1970, ch. 5). Without a field the
// density is never lower than the mean, so the estimate never makes a possible run look
// impossible by more than the estimate's own factor of order one.
struct FlightEstimate {
  double mean_free_path = 0.0, mean_free_time = 0.0;
};
// n particles in a volume, sigma: their mean diameter (or one of the same volume), v_rms.
template <int D>
FlightEstimate estimate_flight(double n, double volume, double sigma, double v_rms) {
  const double density = n / volume;
  FlightEstimate e;
  e.mean_free_path = D == 3 ? 1.0 / (std::sqrt(2.0) * density * M_PI * sigma * sigma)
                            : 1.0 / (2.0 * std::sqrt(2.0) * density * sigma);
  e.mean_free_time = v_rms > 0.0 ? e.mean_free_path / v_rms : kNeverTime;
  return e;
}

// The diameter of the sphere (disk) of the mean particle volume (area).
template <int D>
double mean_volume_diameter(double particle_volume, double n) {
  const double v = particle_volume / n;
  return D == 3 ? std::cbrt(6.0 * v / M_PI) : std::sqrt(4.0 * v / M_PI);
}

// A run measured in collisions in a system that can hardly collide (two particles in a box of
// 1e9, diameters of 1e-30) would run for ever: InputError when a phase of `collisions` (its
// target collision count) would take more than 1e15 units of work, given the work one
// collision takes (events per collision, or DEM steps per collision).
inline void check_collisions_can_happen(double work_per_collision, double collisions,
                                        const FlightEstimate& flight, const char* unit) {
  if (!(work_per_collision * collisions > 1e15)) return;
  throw InputError(fmt::format(
      "the run is measured in collisions, but this system hardly ever collides: the mean free "
      "path is about {:.3g} (mean free time {:.3g}), so each collision takes some {:.3g} {} and "
      "the run some {:.3g}; give its length in simulated time instead (run.time, "
      "run.equilibration_time), or check the box and the diameters",
      flight.mean_free_path, flight.mean_free_time, work_per_collision, unit,
      work_per_collision * collisions));
}

// A phase's output schedule, in collisions or in time (intervals_in_time): the other part of
// the pair is empty, never due. begin, begin_time: where the phase starts.
template <class ToCollisions>
std::pair<OutputSchedule, TimeSchedule> phase_schedules(const Config& c, std::uint64_t begin,
                                                        double begin_time,
                                                        ToCollisions&& collisions_for) {
  const double production = production_length(c.run).value;
  if (intervals_in_time(c))
    return {OutputSchedule{}, TimeSchedule(c.output, production, begin_time)};
  return {OutputSchedule(c.output, production, begin, collisions_for), TimeSchedule{}};
}

}  // namespace kairos::run_detail

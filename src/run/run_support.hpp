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
#include "dem/dem_integrator.hpp"
#include "io/atomic_file.hpp"
#include "io/config.hpp"
#include "io/gsd_file.hpp"
#include "io/gsd_snapshot.hpp"
#include "run/run.hpp"

namespace kairos::run_detail {

namespace fs = std::filesystem;

// The state a run starts from: the restart file (its progress into `progress`), else
// system.initial_state, else a generated one (run/run.cpp).
template <int D>
ParticleSystem<D> build_start_state(const Config& config,
                                    const std::optional<fs::path>& restart_file,
                                    std::mt19937_64& rng, RunProgress& progress);

// Whether SIGINT/SIGTERM asked the run to stop (request_stop()).
bool stop_requested() noexcept;

// run.integrator = "dem" (run/dem_run.cpp).
template <int D>
RunOutcome run_dem(const Config& config, const std::optional<fs::path>& restart_file);

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

// Creates the output directory and writes the effective configuration into it.
inline fs::path prepare_output_directory(const Config& config) {
  const fs::path dir = config.output.directory;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    throw InputError("output.directory: cannot create '" + dir.string() + "': " + ec.message());
  }
  write_text_atomically(dir / "config.toml", to_toml(config));
  return dir;
}

// trajectory.gsd of the run in `dir`: appended to when a restarted run finds its own system's
// file there, else created with `first_frame` (a callable giving the state) as frame 0.
template <int D, class FirstFrame>
void open_trajectory(std::optional<gsd::Writer>& writer, const fs::path& dir, bool restarted,
                     std::size_t n, FirstFrame&& first_frame) {
  const fs::path traj = dir / "trajectory.gsd";
  if (restarted && fs::exists(traj)) {
    check_same_trajectory(traj, n, D, dir);
    writer.emplace(gsd::Writer::open_append(traj));
  } else {
    writer.emplace(gsd::Writer::create(traj, "kairos " KAIROS_VERSION));
    append_trajectory_frame(*writer, first_frame());
  }
}

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

inline void add_run_totals(nlohmann::json& j, const RunTotals& r, const Thermodynamics& th) {
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
  j["compressibility"] = {{"mean", r.compressibility},
                          {"stderr", z_blocks.stderr_},
                          {"blocks", z_blocks.samples},
                          {"method", "Flyvbjerg-Petersen blocking over thermo rows"}};
  j["pressure"] = th.pressure(r.compressibility, r.production_temperature);
  j["production_temperature"] = r.production_temperature;
  j["mean_free_time"] = th.mean_free_time(r.production_time, r.production_collisions);
  j["mean_free_time_stderr"] = th.mean_free_time_blocks().stderr_;
}

inline std::uint64_t peak_rss_bytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<std::uint64_t>(usage.ru_maxrss) * 1024u;
}

class ThermoWriter {
 public:
  ThermoWriter(const fs::path& path, bool append) {
    const bool header = !append || !fs::exists(path) || fs::file_size(path) == 0;
    out_.open(path, append ? std::ios::app : std::ios::trunc);
    if (!out_) throw InputError("cannot write '" + path.string() + "'");
    if (header) {
      write_line(
          "phase\ttime\tevents\tcollisions\tcollisions_per_particle\ttemperature\tpressure\t"
          "compressibility\tkinetic_energy\tmean_free_time\trotational_temperature\t"
          "dissipated_energy\twall_work\tpotential_energy\n");
    }
  }
  // One row per line, each flushed at once: an interrupted run keeps every earlier row.
  // Granular columns: rotational temperature, and the energy dissipated and the work done by
  // moving walls since the start of the simulation (zero for elastic hard spheres).
  // potential_energy: of the stepped potentials (0 for hard spheres), or the elastic energy of
  // the overlapping soft pairs (DEM).
  struct Granular {
    double rotational_temperature = 0.0, dissipated = 0.0, wall_work = 0.0;
    double potential_energy = 0.0;
  };
  void write(const std::string& phase, const ThermoRow& r, const Granular& g) {
    write_line(fmt::format(
        "{}\t{:.17g}\t{}\t{}\t{:.10g}\t{:.17g}\t{:.17g}\t{:.17g}\t{:.17g}\t{:.17g}\t{:.17g}\t"
        "{:.17g}\t{:.17g}\t{:.17g}\n",
        phase, r.at.time, r.at.events, r.at.collisions, r.collisions_per_particle, r.temperature,
        r.pressure, r.compressibility, r.kinetic_energy, r.mean_free_time, g.rotational_temperature,
        g.dissipated, g.wall_work, g.potential_energy));
  }

 private:
  void write_line(const std::string& line) {
    out_ << line;
    out_.flush();
  }

  std::ofstream out_;
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
  write_restart(path, s, rng, progress);
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

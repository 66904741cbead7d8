#include "run/setup_chain.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>

#include <fmt/format.h>

#include "core/periodic.hpp"
#include "io/config_choices.hpp"
#include "io/gsd_file.hpp"
#include "run/dem_adapter.hpp"
#include "run/environment_setup.hpp"
#include "run/event_adapter.hpp"
#include "run/start_state.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"
#include "scheduler/tournament_tree_queue.hpp"

namespace kairos {

namespace {

namespace fs = std::filesystem;

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

// A restart under a configuration that changed (run/restart_plan.hpp): the plan, and, when the
// run re-predicts, the restored state made ready for a fresh prediction: sleepers woken where
// they rest (their rest was decided under the old physics), the stepped potentials' zones
// recomputed from the distances if a potential or bond changed, the DEM's own state dropped.
// InputError for a refused change.
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
      const Vec<D> x = state.position(i, state.time), v = state.velocity(i, state.time);
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

// A restart file continues only under the integrator that wrote it.
void check_restart_integrator(const std::optional<fs::path>& restart_file,
                              const RunProgress& resumed, std::string_view integrator) {
  if (!restart_file || resumed.integrator == integrator) return;
  throw InputError(
      fmt::format("restart file '{}' was written by run.integrator = \"{}\", this run uses \"{}\"; "
                  "continue it with the same integrator, or start a new run from its state with "
                  "system.initial_state",
                  restart_file->string(), resumed.integrator, integrator));
}

// Steps 2 to 4 under the restart's name for errors; `make` builds the integrator.
template <int D, class Make>
auto named_restart_errors(const RunStart<D>& start, Make&& make) {
  try {
    return make();
  } catch (const InputError& e) {
    if (!start.restart_file) throw;
    throw restart_setup_error(e, *start.restart_file, *start.plan);
  }
}

}  // namespace

template <int D>
RunStart<D> start_run(const Config& config, const std::optional<fs::path>& restart_file,
                      std::string_view integrator) {
  RunStart<D> start{config, restart_file, {}, {}, std::mt19937_64(config.system.seed), {}, {}};
  start.state = build_start_state<D>(config, restart_file, start.rng, start.resumed);
  if (!restart_file) {
    CompressConfig compress = config.compress;
    if (!compress.on() && grows_random_start(config))
      compress.packing_fraction = config.system.packing_fraction;
    if (compress.on()) {
      const bool tell = progress_modes().at(config.output.progress) != ProgressMode::kOff;
      start.compression = compress_start<D>(
          start.state, compress, config.system.temperature, tell, config.run.size_levels,
          growth_environment(make_environment<D>(config, start.state)));
    }
  }
  check_restart_integrator(restart_file, start.resumed, integrator);
  if (restart_file) {
    start.plan = plan_continuation<D>(config, start.state, start.resumed, restart_file->string());
    start.config = start.plan->used;
  }
  return start;
}

SoftTableSettings soft_table_settings(const Config& config, const RunProgress& resumed) {
  SoftTableSettings settings;
  settings.tolerance = config.soft.table_tolerance;
  settings.cache_dir = config.soft.table_cache;
  settings.max_speed = resumed.soft_table_max_speed;  // 0 (from the state) for a new run
  if (driving_kinds().is(config.driving.kind, DrivingKind::kAndersen))
    settings.driving_temperature = config.driving.temperature;
  return settings;
}

template <int D>
std::vector<SoftTableUse> start_tables(Environment<D>& environment, const RunStart<D>& start,
                                       const TableProgress& progress) {
  if (!environment.soft_spheres() || !start.config.soft.tables) return {};
  return attach_soft_tables(environment, start.state,
                            soft_table_settings(start.config, start.resumed), progress);
}

// A wall with mass that nothing pushes into the box (no inward force, no field towards the
// particles) is carried off by them for as long as the run lasts, the gas expanding after it:
// physics, but rarely what was meant, and ever slower (docs/config.md).
template <int D>
void note_walls_carried_off(const Environment<D>& environment) {
  for (int f = 0; f < 2 * D; ++f) {
    const Wall<D>& w = environment.faces[f].wall;
    if (environment.faces[f].kind != FaceKind::kWall || !w.massive()) continue;
    if (w.joined || w.spring.on()) continue;  // a container: the other wall holds the particles
    if (w.inward_push(f, environment.gravity) > 0.0) continue;
    std::fputs(fmt::format("kairos: note: boundary.wall ({}{}) has mass but nothing pushes it "
                           "into the box (its force and the field): the particles will carry "
                           "it off for as long as the run lasts\n",
                           "xyz"[f / 2], f % 2 == 0 ? '-' : '+')
                   .c_str(),
               stderr);
  }
}

template <int D, class Queue>
std::unique_ptr<EventEngineAdapter<D, Queue>> start_event_engine(RunStart<D>&& start,
                                                                 const TableProgress& progress,
                                                                 const EngineTracking& tracking) {
  return named_restart_errors(start, [&] {
    Environment<D> environment = make_environment<D>(start.config, start.state);
    note_walls_carried_off(environment);
    std::vector<SoftTableUse> tables = start_tables(environment, start, progress);
    // A mixture's thermal conductivity needs its components' mass moments (a component: one
    // species and one mass): unwrapped positions.
    EngineTracking tracked = tracking;
    const ParticleSystem<D>& state = start.state;
    bool mixture = false;
    for (std::size_t i = 1; i < state.size() && !mixture; ++i) {
      mixture = state.mass[i] != state.mass[0] ||
                (!state.species.empty() && state.species[i] != state.species[0]);
    }
    tracked.images =
        tracked.images || (mixture && (start.config.analysis.transport || tracking.helfand));
    return std::make_unique<EventEngineAdapter<D, Queue>>(std::move(start), environment,
                                                          std::move(tables), tracked);
  });
}

template <int D>
std::unique_ptr<Integrator<D>> start_integrator(RunStart<D>&& start,
                                                const TableProgress& progress) {
  const RunConfig& run = start.config.run;
  if (integrators().at(run.integrator) == IntegratorKind::kDem) {
    return named_restart_errors(start, [&]() -> std::unique_ptr<Integrator<D>> {
      const Environment<D> environment = make_environment<D>(start.config, start.state);
      return std::make_unique<DemAdapter<D>>(std::move(start), environment);
    });
  }
  switch (event_queues().at(run.event_queue)) {
    case EventQueue::kHeap:
      return start_event_engine<D, BinaryHeapQueue>(std::move(start), progress);
    case EventQueue::kTree:
      return start_event_engine<D, TournamentTreeQueue>(std::move(start), progress);
    case EventQueue::kCalendar:
      break;
  }
  return start_event_engine<D, CalendarQueue>(std::move(start), progress);
}

InputError restart_setup_error(const InputError& e, const fs::path& restart_file,
                               const RestartPlan& plan) {
  if (plan.repredict && plan.stored_config) {
    return InputError(fmt::format("restart file '{}' continued with new physics ({}): {}",
                                  restart_file.string(), fmt::join(plan.changed, ", "), e.what()));
  }
  return InputError("restart file '" + restart_file.string() + "': " + e.what());
}

void print_restart_note(const RestartPlan& plan, const std::string& restart_file) {
  const std::string note = describe_restart(plan, restart_file);
  if (!note.empty())
    std::fputs(fmt::format("kairos: note: restart from '{}': {}\n", restart_file, note).c_str(),
               stderr);
}

#define KAIROS_SETUP_CHAIN(D)                                                             \
  template RunStart<D> start_run<D>(const Config&, const std::optional<fs::path>&,        \
                                    std::string_view);                                    \
  template std::vector<SoftTableUse> start_tables<D>(Environment<D>&, const RunStart<D>&, \
                                                     const TableProgress&);               \
  template std::unique_ptr<Integrator<D>> start_integrator<D>(RunStart<D>&&,              \
                                                              const TableProgress&);      \
  template std::unique_ptr<EventEngineAdapter<D, CalendarQueue>>                          \
  start_event_engine<D, CalendarQueue>(RunStart<D>&&, const TableProgress&,               \
                                       const EngineTracking&);
KAIROS_SETUP_CHAIN(2)
KAIROS_SETUP_CHAIN(3)
#undef KAIROS_SETUP_CHAIN

}  // namespace kairos

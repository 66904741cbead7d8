#include "run/run_progress.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <vector>

#include "core/error.hpp"
#include "io/gsd_file.hpp"
#include "io/gsd_reading.hpp"
#include "io/gsd_snapshot.hpp"

namespace kairos {

namespace {

using gsd_read::require;

void write_progress(gsd::Writer& w, const RunProgress& progress) {
  w.write_chunk("kairos/run/next_kick_time", 1, 1, &progress.next_kick_time);
  w.write_chunk("kairos/run/equilibration_remaining", 1, 1, &progress.equilibration_remaining);
  if (std::isfinite(progress.equilibration_end_time)) {
    w.write_chunk("kairos/run/equilibration_end_time", 1, 1, &progress.equilibration_end_time);
  }
  if (progress.soft_table_max_speed > 0.0) {
    w.write_chunk("kairos/run/soft_table_max_speed", 1, 1, &progress.soft_table_max_speed);
  }
  if (!progress.config.empty()) {
    const std::vector<std::int8_t> text(progress.config.begin(), progress.config.end());
    w.write_chunk("kairos/run/config", text.size(), 1, text.data());
  }
  if (!progress.run_id.empty()) {
    const std::vector<std::int8_t> id(progress.run_id.begin(), progress.run_id.end());
    w.write_chunk("kairos/run/id", id.size(), 1, id.data());
  }
  if (progress.thermo_rows >= 0 || progress.trajectory_frames >= 0) {
    const std::int64_t outputs[2] = {progress.thermo_rows, progress.trajectory_frames};
    w.write_chunk("kairos/run/outputs", 2, 1, outputs);
  }
  if (progress.owed_outputs != 0) {
    const auto owed = static_cast<std::uint8_t>(progress.owed_outputs);
    w.write_chunk("kairos/run/owed", 1, 1, &owed);
  }
  for (const auto& [name, m] : progress.marks) {
    const auto declared = std::find_if(std::begin(kProgressMarks), std::end(kProgressMarks),
                                       [&](const ProgressMarkDecl& d) { return d.name == name; });
    if (declared == std::end(kProgressMarks))
      throw std::logic_error("restart mark '" + name + "' is not declared in kProgressMarks");
    if (m.values.size() != declared->values || m.counts.size() != declared->counts)
      throw std::logic_error("restart mark '" + name + "' does not have its declared sizes");
  }
  for (const ProgressMarkDecl& d : kProgressMarks) {
    const ProgressMark* m = progress.mark(d.name);
    if (m == nullptr) continue;
    const std::string name = "kairos/run/" + std::string(d.name);
    w.write_chunk(name, d.values, 1, m->values.data());
    w.write_chunk(name + std::string(d.counts_suffix), d.counts, 1, m->counts.data());
  }
  if (progress.schedule_phase >= 0) {
    std::uint64_t schedule[7];
    schedule[0] = static_cast<std::uint64_t>(progress.schedule_phase);
    for (int k = 0; k < 3; ++k) {
      schedule[1 + k] = progress.schedule_step[k];
      schedule[4 + k] = progress.schedule_next[k];
    }
    w.write_chunk("kairos/run/schedule", 7, 1, schedule);
  }
  if (progress.production_target > 0)
    w.write_chunk("kairos/run/production_target", 1, 1, &progress.production_target);
  if (std::isfinite(progress.production_end_time))
    w.write_chunk("kairos/run/production_end_time", 1, 1, &progress.production_end_time);
  if (progress.integrator != "event") {
    const std::vector<std::int8_t> name(progress.integrator.begin(), progress.integrator.end());
    w.write_chunk("kairos/run/integrator", name.size(), 1, name.data());
    w.write_chunk("kairos/run/dem_time_step", 1, 1, &progress.dem_time_step);
    w.write_chunk("kairos/run/dem_collision_mark", 1, 1, &progress.dem_collision_mark);
    if (std::isfinite(progress.dem_time_mark))
      w.write_chunk("kairos/run/dem_time_mark", 1, 1, &progress.dem_time_mark);
  }
}

// `s`: the state read from the same frame (marks after it are refused).
template <int D>
void read_progress(const gsd::Reader& r, std::uint64_t f, const std::filesystem::path& path,
                   const ParticleSystem<D>& s, RunProgress& progress) {
  progress = {};
  std::string file = "'";  // (not "'" + ...: a GCC 12 -Wrestrict false positive)
  file += path.string();
  file += '\'';
  if (r.find(f, "kairos/run/equilibration_remaining")) {
    const double left = require<double>(r, f, "kairos/run/equilibration_remaining", path, 1)[0];
    if (!std::isfinite(left) || left < 0.0) {
      throw InputError(file + ": kairos/run/equilibration_remaining is " + std::to_string(left));
    }
    progress.equilibration_remaining = left;
  }
  if (r.find(f, "kairos/run/equilibration_end_time")) {
    const double end = require<double>(r, f, "kairos/run/equilibration_end_time", path, 1)[0];
    if (!std::isfinite(end))
      throw InputError(file + ": kairos/run/equilibration_end_time is not finite");
    progress.equilibration_end_time = end;
  }
  if (r.find(f, "kairos/run/next_kick_time"))
    progress.next_kick_time = require<double>(r, f, "kairos/run/next_kick_time", path, 1)[0];
  if (r.find(f, "kairos/run/soft_table_max_speed")) {
    const double v = require<double>(r, f, "kairos/run/soft_table_max_speed", path, 1)[0];
    if (!(v > 0.0) || !std::isfinite(v)) {
      throw InputError(file + ": kairos/run/soft_table_max_speed is " + std::to_string(v));
    }
    progress.soft_table_max_speed = v;
  }
  if (r.find(f, "kairos/run/config")) {
    const auto text = r.read<std::int8_t>(f, "kairos/run/config");
    progress.config.assign(text.begin(), text.end());
  }
  if (r.find(f, "kairos/run/id")) {  // optional (files written before run ids)
    const auto id = r.read<std::int8_t>(f, "kairos/run/id");
    progress.run_id.assign(id.begin(), id.end());
    const bool plain = !progress.run_id.empty() && progress.run_id.size() <= 64 &&
                       std::all_of(progress.run_id.begin(), progress.run_id.end(), [](char c) {
                         return std::isalnum(static_cast<unsigned char>(c));
                       });
    if (!plain) throw InputError(file + ": corrupt kairos/run/id (not a run id)");
  }
  if (r.find(f, "kairos/run/outputs")) {
    const auto outputs = require<std::int64_t>(r, f, "kairos/run/outputs", path, 2);
    progress.thermo_rows = std::max<std::int64_t>(-1, outputs[0]);
    progress.trajectory_frames = std::max<std::int64_t>(-1, outputs[1]);
  }
  if (r.find(f, "kairos/run/owed")) {
    const auto owed = require<std::uint8_t>(r, f, "kairos/run/owed", path, 1)[0];
    if (owed > (RunProgress::kOwedRow | RunProgress::kOwedFrame))
      throw InputError(file + ": kairos/run/owed is not a set of outputs");
    progress.owed_outputs = owed;
  }
  for (const ProgressMarkDecl& d : kProgressMarks) {
    const std::string name = "kairos/run/" + std::string(d.name);
    if (!r.find(f, name)) continue;
    ProgressMark m;
    m.values = require<double>(r, f, name, path, d.values);
    m.counts = require<std::uint64_t>(r, f, name + std::string(d.counts_suffix), path, d.counts);
    for (const double x : m.values)
      if (!std::isfinite(x)) throw InputError(file + ": " + name + " is not finite");
    if (m.values[0] > s.time || m.counts.back() > s.counters.collisions)
      throw InputError(file + ": " + name + " lies after the state");
    progress.marks.emplace(std::string(d.name), std::move(m));
  }
  if (r.find(f, "kairos/run/schedule")) {
    const auto schedule = require<std::uint64_t>(r, f, "kairos/run/schedule", path, 7);
    if (schedule[0] > 1) throw InputError(file + ": corrupt kairos/run/schedule");
    progress.schedule_phase = static_cast<int>(schedule[0]);
    for (int k = 0; k < 3; ++k) {
      progress.schedule_step[k] = schedule[1 + k];
      progress.schedule_next[k] = schedule[4 + k];
    }
  }
  if (r.find(f, "kairos/run/production_target"))
    progress.production_target =
        require<std::uint64_t>(r, f, "kairos/run/production_target", path, 1)[0];
  if (r.find(f, "kairos/run/production_end_time")) {
    progress.production_end_time =
        require<double>(r, f, "kairos/run/production_end_time", path, 1)[0];
    if (!std::isfinite(progress.production_end_time))
      throw InputError(file + ": kairos/run/production_end_time is not finite");
  }
  if (r.find(f, "kairos/run/integrator")) {
    const auto name = r.read<std::int8_t>(f, "kairos/run/integrator");
    progress.integrator.assign(name.begin(), name.end());
    progress.dem_time_step = require<double>(r, f, "kairos/run/dem_time_step", path, 1)[0];
    if (r.find(f, "kairos/run/dem_collision_mark")) {
      progress.dem_collision_mark =
          require<std::uint64_t>(r, f, "kairos/run/dem_collision_mark", path, 1)[0];
    }
    if (r.find(f, "kairos/run/dem_time_mark")) {
      progress.dem_time_mark = require<double>(r, f, "kairos/run/dem_time_mark", path, 1)[0];
      if (!std::isfinite(progress.dem_time_mark))
        throw InputError(file + ": kairos/run/dem_time_mark is not finite");
    }
    if (!(progress.dem_time_step > 0.0) || !std::isfinite(progress.dem_time_step)) {
      throw InputError(file + ": kairos/run/dem_time_step is " +
                       std::to_string(progress.dem_time_step));
    }
  }
}

}  // namespace

template <int D>
void write_restart_file(const std::filesystem::path& path, const StateBlocks<D>& state,
                        const std::mt19937_64& rng, const RunProgress& progress) {
  write_restart(path, state, rng, [&](gsd::Writer& w) { write_progress(w, progress); });
}

template <int D>
void write_restart_file(const std::filesystem::path& path, const ParticleSystem<D>& state,
                        const std::mt19937_64& rng, const RunProgress& progress) {
  write_restart_file(path, StateBlocks<D>::of(state), rng, progress);
}

template <int D>
ParticleSystem<D> read_restart_file(const std::filesystem::path& path, std::mt19937_64& rng,
                                    RunProgress& progress, RunKind kind) {
  return read_restart<D>(path, rng, kind,
                         [&](const gsd::Reader& r, std::uint64_t f, const ParticleSystem<D>& s) {
                           read_progress(r, f, path, s, progress);
                         });
}

template void write_restart_file<2>(const std::filesystem::path&, const StateBlocks<2>&,
                                    const std::mt19937_64&, const RunProgress&);
template void write_restart_file<3>(const std::filesystem::path&, const StateBlocks<3>&,
                                    const std::mt19937_64&, const RunProgress&);
template void write_restart_file<2>(const std::filesystem::path&, const ParticleSystem<2>&,
                                    const std::mt19937_64&, const RunProgress&);
template void write_restart_file<3>(const std::filesystem::path&, const ParticleSystem<3>&,
                                    const std::mt19937_64&, const RunProgress&);
template ParticleSystem<2> read_restart_file<2>(const std::filesystem::path&, std::mt19937_64&,
                                                RunProgress&, RunKind);
template ParticleSystem<3> read_restart_file<3>(const std::filesystem::path&, std::mt19937_64&,
                                                RunProgress&, RunKind);

}  // namespace kairos

#include "run/outputs/thermo_output.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <fstream>

#include "analysis/block_average.hpp"
#include "core/error.hpp"
#include "run/outputs/summary_values.hpp"
#include "run/phase_length.hpp"

namespace kairos {

template <int D>
bool completes_production(const RunContext<D>& run) {
  const RunProgress& r = run.resumed();
  const std::optional<RestartPlan>& plan = run.plan();
  return run.restarted() && run.continuation().same_directory &&
         r.mark("production_start") != nullptr &&
         (r.production_target > 0 || std::isfinite(r.production_end_time)) && plan &&
         !plan->repredict && !length_given_anew(plan);
}

namespace {

std::vector<std::string> split_tabs(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t tab = line.find('\t', start);
    out.push_back(line.substr(start, tab - start));
    if (tab == std::string::npos) return out;
    start = tab + 1;
  }
}

}  // namespace

template <int D>
void ThermoOutput<D>::continue_production(const RunContext<D>& run) {
  const ProgressMark& m = *run.resumed().mark("production_start");
  production_start_ = {m.values[0], m.values[1], m.counts[0], m.counts[1]};
  production_ke_ = m.values[2];
  production_held_ = m.values[3];
  production_started_ = production_continued_ = true;
  // The kept rows (the file was cut to them): every value as written, %.17g, read back exactly.
  const std::filesystem::path path = run.directory() / name();
  std::ifstream in(path);
  std::string line;
  if (!std::getline(in, line)) throw InputError(path.string() + ": cannot read its header");
  earlier_columns_ = split_tabs(line);
  earlier_rows_.assign(earlier_columns_.size(), {});
  while (std::getline(in, line)) {
    const std::vector<std::string> fields = split_tabs(line);
    if (fields.empty() || fields[0] != "production") continue;
    if (fields.size() != earlier_columns_.size()) {
      throw InputError(fmt::format("{}: a production row with {} columns, not the header's {}",
                                   path.string(), fields.size(), earlier_columns_.size()));
    }
    for (std::size_t k = 1; k < fields.size(); ++k)
      earlier_rows_[k].push_back(std::strtod(fields[k].c_str(), nullptr));
  }
  // As Thermodynamics::row and write_row keep them.
  std::vector<double> z, mft;
  if (const auto* column = earlier_production_column("compressibility"))
    for (const double x : *column)
      if (std::isfinite(x)) z.push_back(x);
  if (const auto* column = earlier_production_column("mean_free_time"))
    for (const double x : *column)
      if (std::isfinite(x)) mft.push_back(x);
  stats_->restore_production_rows(std::move(z), std::move(mft));
  if (const auto* column = earlier_production_column("temperature"))
    production_temperatures_ = *column;
  if (const auto* column = earlier_production_column("potential_energy"))
    production_potential_energies_ = *column;
}

template <int D>
const std::vector<double>* ThermoOutput<D>::earlier_production_column(
    const std::string& column) const {
  if (!production_continued_) return nullptr;
  for (std::size_t k = 1; k < earlier_columns_.size(); ++k)
    if (earlier_columns_[k] == column) return &earlier_rows_[k];
  return nullptr;
}

template <int D>
void ThermoOutput<D>::open(const RunContext<D>& run) {
  const Integrator<D>& integrator = run.integrator();
  const std::filesystem::path path = run.directory() / name();
  std::string header(kHeader);
  const std::vector<WallReading> walls = integrator.walls_with_mass();
  if (!walls.empty() || integrator.outlet()) {
    header.pop_back();  // its newline
    for (const WallReading& w : walls) {
      header += fmt::format("\twall_{0}_position\twall_{0}_speed\twall_{0}_energy", w.face);
      if (w.sprung) header += fmt::format("\twall_{0}_drive_work\twall_{0}_dashpot", w.face);
    }
    if (integrator.outlet()) header += "\toutlet_passes\toutlet_mass\toutlet_energy";
    header += '\n';
  }
  // A new file, or (a continued run) the existing one cut to the rows the continued state had
  // written (all complete rows when not recorded).
  file_.emplace(run.restarted() ? LineFile(path, header, run.continuation().thermo_rows)
                                : LineFile::create(path, header));
  rows_kept_ = file_->rows();
  stats_.emplace(D, integrator.mobile(), integrator.volume(),
                 integrator.mobile() < integrator.size());
  events_start_ = integrator.events();
  collisions_start_ = integrator.collisions();
  // Continued in its own directory: the next row covers the interval from the last kept one.
  const ProgressMark* mark = run.resumed().mark("thermo_mark");
  kept_mark_ = run.continuation().same_directory && mark != nullptr
                   ? ThermoPoint{mark->values[0], mark->values[1], mark->counts[0], mark->counts[1]}
                   : integrator.point();
  stats_->mark(kept_mark_);
  if (completes_production(run)) continue_production(run);
}

template <int D>
bool ThermoOutput<D>::pending(const RunContext<D>& run) const {
  const Integrator<D>& integrator = run.integrator();
  return integrator.collisions() > stats_->last().collisions ||
         (run.timed() && integrator.time() > stats_->last().time);
}

// The columns of the walls with mass and of the outlet (empty without).
template <int D>
std::string wall_columns(const Integrator<D>& integrator) {
  std::string out;
  for (const WallReading& w : integrator.walls_with_mass()) {
    out += fmt::format("\t{:.17g}\t{:.17g}\t{:.17g}", w.position, w.speed, w.energy);
    if (w.sprung) out += fmt::format("\t{:.17g}\t{:.17g}", w.drive_work, w.dashpot);
  }
  if (const auto outlet = integrator.outlet())
    out += fmt::format("\t{}\t{:.17g}\t{:.17g}", outlet->passes, outlet->mass, outlet->energy);
  return out;
}

// One row per line. Granular columns: rotational temperature per rotational degree of freedom
// (3 for spheres, 1 for disks; 0 without spins), and the energy dissipated and the work done by
// moving walls since the start of the simulation (zero for elastic hard spheres);
// potential_energy: of the stepped potentials (0 for hard spheres), or the elastic energy of
// the overlapping soft pairs (DEM).
template <int D>
void ThermoOutput<D>::write_row(const RunContext<D>& run, const std::string& phase, bool kept) {
  const Integrator<D>& integrator = run.integrator();
  const bool production = phase == "production";
  if (production) run.sample_production_row();
  const ThermoRow r = stats_->row(integrator.point(), integrator.thermal_energy(), production,
                                  integrator.held_degrees_of_freedom());
  if (production) {
    production_temperatures_.push_back(r.temperature);
    production_potential_energies_.push_back(integrator.potential_energy());
  }
  const double rotational_temperature =
      2.0 * integrator.rotational_energy() /
      ((D == 3 ? 3.0 : 1.0) * static_cast<double>(integrator.mobile()));
  file_->append(fmt::format(
      "{}\t{:.17g}\t{}\t{}\t{:.10g}\t{:.17g}\t{:.17g}\t{:.17g}\t{:.17g}\t{:.17g}\t{:.17g}\t"
      "{:.17g}\t{:.17g}\t{:.17g}{}\n",
      phase, r.at.time, r.at.events, r.at.collisions, r.collisions_per_particle, r.temperature,
      r.pressure, r.compressibility, r.kinetic_energy, r.mean_free_time, rotational_temperature,
      integrator.dissipated_energy(), integrator.work_by_walls(), integrator.potential_energy(),
      wall_columns(integrator)));
  if (kept) {
    rows_kept_ = file_->rows();
    kept_mark_ = r.at;
  }
}

template <int D>
void ThermoOutput<D>::equilibration_ends(const RunContext<D>& run, bool stopped) {
  if (pending(run)) write_row(run, "equilibration", !stopped);
}

template <int D>
void ThermoOutput<D>::production_starts(const RunContext<D>& run) {
  if (production_continued_) return;  // an earlier invocation's, restored
  production_started_ = true;
  production_start_ = run.integrator().point();
  production_ke_ = run.integrator().thermal_energy();
  production_held_ = run.integrator().held_degrees_of_freedom();
}

template <int D>
void ThermoOutput<D>::close(const RunContext<D>& run, bool stopped) {
  if (pending(run)) write_row(run, run.phase(), !stopped);
}

template <int D>
void ThermoOutput<D>::record(RunProgress& progress) const {
  progress.thermo_rows = static_cast<std::int64_t>(rows_kept_);
  progress.marks["thermo_mark"] = {{kept_mark_.time, kept_mark_.virial},
                                   {kept_mark_.events, kept_mark_.collisions}};
  // Kept by the driver only for an unfinished production (RunDriver::progress_now).
  if (production_started_) {
    progress.marks["production_start"] = {
        {production_start_.time, production_start_.virial, production_ke_, production_held_},
        {production_start_.events, production_start_.collisions}};
  }
}

template <int D>
double ThermoOutput<D>::production_temperature(const Integrator<D>& integrator) const {
  return stats_->span_temperature(integrator.temperature_from_rows(), production_temperatures_,
                                  production_ke_, production_held_);
}

template <int D>
BlockAverage ThermoOutput<D>::production_compressibility(const Integrator<D>& integrator) const {
  BlockAverage z = stats_->compressibility_blocks();
  z.mean = stats_->compressibility(integrator.virial() - production_start_.virial,
                                   production_temperature(integrator),
                                   integrator.time() - production_start_.time);
  return z;
}

// summary.json's run totals (docs/outputs.md): counts and rates of this invocation, the times,
// the temperature, Z with its blocked error, the pressure and the mean free time. Z and the
// pressure are bulk values: undefined with walls, open faces or a field.
template <int D>
void ThermoOutput<D>::summarize(nlohmann::json& j, const RunContext<D>& run) const {
  const Integrator<D>& integrator = run.integrator();
  const Thermodynamics& th = *stats_;
  const double wall = run.wall_seconds();
  const std::uint64_t events = integrator.events() - events_start_;
  const std::uint64_t collisions = integrator.collisions() - collisions_start_;
  const double production_time = integrator.time() - production_start_.time;
  const std::uint64_t production_collisions =
      integrator.collisions() - production_start_.collisions;
  const double ke = integrator.thermal_energy();
  const double kT_production = production_temperature(integrator);
  const BlockAverage z_blocks = production_compressibility(integrator);
  const double z_mean = z_blocks.mean;
  // Z and the mean free time of a system with potentials follow its configurational energy,
  // whose slow relaxation the rows' fast collisional noise hides from their own blocking (a
  // lag-1 correlation of a few per cent): their error bars are reliable only when U's is (U is
  // constant, so reliable, for hard particles). docs/physics.md, "Statistical errors".
  const bool u_steady = block_average(production_potential_energies_).reliable;
  j["events"] = events;
  j["collisions"] = collisions;
  j["sim_time"] = integrator.time();
  j["production_time"] = production_time;
  j["production_collisions_per_particle"] = run.per_particle(production_collisions);
  j["wall_seconds"] = wall;
  j["setup_wall_seconds"] = run.setup_wall_seconds();
  j["events_per_second"] = wall > 0 ? static_cast<double>(events) / wall : 0.0;
  j["collisions_per_second"] = wall > 0 ? static_cast<double>(collisions) / wall : 0.0;
  j["temperature"] = th.temperature(ke, integrator.held_degrees_of_freedom());
  j["kinetic_energy"] = ke;
  const std::string why =
      pressure_undefined_reason(integrator.bulk(), integrator.mobile() < integrator.size(),
                                production_time, kT_production, "production time");
  nlohmann::json z = {
      {"blocks", z_blocks.samples},
      {"method", "blocking over thermo rows (Flyvbjerg-Petersen, level by Jonsson's test)"}};
  set_or_explain(j, z, "mean", z_mean, why, "compressibility");
  const std::string z_stderr_why = !why.empty()           ? why
                                   : z_blocks.samples < 2 ? "fewer than 2 production thermo rows"
                                                          : "";
  set_or_explain(j, z, "stderr", z_blocks.stderr_, z_stderr_why, "compressibility_stderr");
  z["stderr_blocks"] = z_blocks.blocks;
  z["stderr_reliable"] = z_stderr_why.empty() && z_blocks.reliable && u_steady;
  set_or_explain(j, z, "correlation_time_rows", z_blocks.correlation_time, z_stderr_why,
                 "compressibility.correlation_time_rows");
  j["compressibility"] = z;
  set_or_explain(j, j, "pressure", th.pressure(z_mean, kT_production), why, "pressure");
  j["production_temperature"] = kT_production;
  // A continued run says what its production averages cover (a new run: its production).
  if (run.restarted()) {
    j["production_covers"] =
        production_continued_
            ? "the whole production, begun by an earlier invocation of this run in this "
              "directory (completed from its restart file)"
            : "the production of this invocation";
  }
  const std::string no_collision =
      production_collisions == 0 ? "no collision in the production" : "";
  set_or_explain(j, j, "mean_free_time", th.mean_free_time(production_time, production_collisions),
                 no_collision, "mean_free_time");
  const BlockAverage mft_blocks = th.mean_free_time_blocks();
  const std::string mft_stderr_why = !no_collision.empty() ? no_collision
                                     : mft_blocks.samples < 2
                                         ? "fewer than 2 production thermo rows"
                                         : "";
  set_or_explain(j, j, "mean_free_time_stderr", mft_blocks.stderr_, mft_stderr_why,
                 "mean_free_time_stderr");
  j["mean_free_time_stderr_blocks"] = mft_blocks.blocks;
  j["mean_free_time_stderr_reliable"] = mft_stderr_why.empty() && mft_blocks.reliable && u_steady;
}

template bool completes_production<2>(const RunContext<2>&);
template bool completes_production<3>(const RunContext<3>&);
template class ThermoOutput<2>;
template class ThermoOutput<3>;

}  // namespace kairos

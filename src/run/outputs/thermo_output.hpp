// thermo.tsv, one row per thermo interval (docs/outputs.md), and what summary.json averages
// over its rows: the run totals, Z with its blocked error, the pressure, the mean free time and
// the production temperature.
//
// Rows are written whole or not at all (io/line_file.hpp). A continued run cuts the file back
// to the rows its restart state had written and measures the next row from the last kept one
// (the thermo mark), so that the file is one uninterrupted run's. A run with walls with mass
// adds three columns per such wall (wall_<face>_position, _speed, _energy). Production rows are the
// moments analyses sample at (RunContext::sample_production_row).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "analysis/thermodynamics.hpp"
#include "io/line_file.hpp"
#include "run/outputs/observer.hpp"

namespace kairos {

template <int D>
class ThermoOutput final : public Observer<D> {
 public:
  static constexpr const char* kHeader =
      "phase\ttime\tevents\tcollisions\tcollisions_per_particle\ttemperature\tpressure\t"
      "compressibility\tkinetic_energy\tmean_free_time\trotational_temperature\t"
      "dissipated_energy\twall_work\tpotential_energy\n";

  static constexpr std::array<std::string_view, 1> kFiles{"thermo.tsv"};
  std::string name() const override { return std::string(kFiles[0]); }
  // Default: 100 rows per production length.
  double interval(const Config& config, double production) const override {
    return config.output.thermo_interval > 0 ? config.output.thermo_interval : production / 100.0;
  }
  int schedule_slot() const override { return 0; }
  unsigned owed_bit() const override { return RunProgress::kOwedRow; }

  void open(const RunContext<D>& run) override;
  void write(const RunContext<D>& run) override { write_row(run, run.phase(), true); }
  // The equilibration's last row, so that no production row spans both phases (a stopped
  // run's last row is not kept: a continued run writes the rows an uninterrupted one would).
  void equilibration_ends(const RunContext<D>& run, bool stopped) override;
  void production_starts(const RunContext<D>& run) override;
  void close(const RunContext<D>& run, bool stopped) override;
  void record(RunProgress& progress) const override;
  void summarize(nlohmann::json& summary, const RunContext<D>& run) const override;

  // The kT that Z and the pressure use: the kinetic temperature at the start of production, or
  // the mean over the production rows where kinetic energy is exchanged or set
  // (Integrator::temperature_from_rows).
  double production_temperature(const Integrator<D>& integrator) const;
  // Z over this invocation's production, as summary.json's `compressibility` gives it: the mean
  // is the total virial over the total time, stderr and samples come from blocking the
  // production rows' values (NaN mean without production time or at kT = 0).
  BlockAverage production_compressibility(const Integrator<D>& integrator) const;
  const Thermodynamics& statistics() const { return *stats_; }
  // A run completing the production an earlier invocation of it left unfinished, in the same
  // directory with the same physics (completes_production): the kept production rows' column
  // `name` of thermo.tsv as that invocation wrote them (every digit: %.17g), for the observers
  // that sample at the rows (the stepped energy, the walls with mass); null otherwise or for a
  // column the file lacks.
  const std::vector<double>* earlier_production_column(const std::string& name) const;

 private:
  // A row not yet written for the present: new collisions, or (timed) time gone by.
  bool pending(const RunContext<D>& run) const;
  // kept: the row belongs to the run as an uninterrupted one writes it (not the last row of a
  // run stopped early).
  void write_row(const RunContext<D>& run, const std::string& phase, bool kept);

  std::optional<LineFile> file_;
  std::optional<Thermodynamics> stats_;
  // Rows of this directory's file that an uninterrupted run also writes, and the point the
  // last kept row ended at (what a restart file records for a continued run).
  std::uint64_t rows_kept_ = 0;
  ThermoPoint kept_mark_;
  ThermoPoint production_start_;
  double production_ke_ = 0.0;    // thermal energy at the start of production
  double production_held_ = 0.0;  // degrees of freedom held still then (soft contacts)
  std::vector<double> production_temperatures_;
  // U at each production row: the slow variable Z's and the mean free time's rows may hide
  // under their fast noise, so their error bars are reliable only when its own is.
  std::vector<double> production_potential_energies_;
  std::uint64_t events_start_ = 0, collisions_start_ = 0;  // of this invocation
  bool production_started_ = false;
  // The production is an earlier invocation's, continued: its start and rows restored.
  bool production_continued_ = false;
  std::vector<std::string> earlier_columns_;
  std::vector<std::vector<double>> earlier_rows_;  // per column, the kept production rows

  // Restores the production's start from the restart file and its rows from thermo.tsv.
  void continue_production(const RunContext<D>& run);
};

// Whether a continued run completes the production its restart file left unfinished, in the
// same directory (its thermo.tsv holds that production's kept rows) and with the same physics
// (a bit-identical continuation, the run length not given anew): then summary.json's averages
// over the production rows cover the whole production, as one uninterrupted run's.
template <int D>
bool completes_production(const RunContext<D>& run);

}  // namespace kairos

#include "replica/exchange_statistics.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "analysis/block_average.hpp"
#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "replica/replica_exchange.hpp"

namespace kairos {
namespace {

namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

template <class T>
T field(std::string_view text, const fs::path& path, std::size_t line) {
  T value{};
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) {
    throw InputError(fmt::format("{}:{}: '{}' is not a number", path.string(), line, text));
  }
  return value;
}

double mean(const std::vector<double>& x) {
  double s = 0.0;
  for (const double v : x) s += v;
  return x.empty() ? kNaN : s / static_cast<double>(x.size());
}

double variance(const std::vector<double>& x) {
  if (x.size() < 2) return kNaN;
  const double m = mean(x);
  double s = 0.0;
  for (const double v : x) s += (v - m) * (v - m);
  return s / static_cast<double>(x.size());  // the canonical fluctuation <U^2> - <U>^2
}

nlohmann::json finite_or_null(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json();
}

std::string tsv_number(double x) {
  return std::isfinite(x) ? fmt::format("{}", x) : "nan";
}

}  // namespace

ExchangeResults read_exchange_table(const fs::path& path, std::size_t rungs) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot read", path.string()));
  ExchangeResults r;
  r.energy_at.resize(rungs);
  r.replica_at.resize(rungs);
  std::string line;
  std::getline(in, line);  // the header
  for (std::size_t number = 2; std::getline(in, line); ++number) {
    std::vector<std::string_view> f;
    std::string_view rest = line;
    for (;;) {
      const auto tab = rest.find('\t');
      f.push_back(rest.substr(0, tab));
      if (tab == std::string_view::npos) break;
      rest.remove_prefix(tab + 1);
    }
    if (f.size() != 3 + 2 * rungs || f.back().size() + 1 != rungs) {
      throw InputError(fmt::format("{}:{}: {} columns, expected {}", path.string(), number,
                                   f.size(), 3 + 2 * rungs));
    }
    r.swaps.emplace_back(f.back());
    r.round.push_back(field<std::uint64_t>(f[0], path, number));
    r.time.push_back(field<double>(f[1], path, number));
    for (std::size_t k = 0; k < rungs; ++k) {
      r.energy_at[k].push_back(field<double>(f[2 + k], path, number));
      r.replica_at[k].push_back(field<std::uint32_t>(f[2 + rungs + k], path, number));
    }
  }
  return r;
}

Estimate jackknife(const std::vector<double>& samples,
                   const std::function<double(const std::vector<double>&)>& statistic,
                   std::size_t most_blocks) {
  Estimate e{statistic(samples), kNaN};
  const std::size_t blocks = std::min(most_blocks, samples.size() / 2);
  if (blocks < 2) return e;
  const std::size_t size = samples.size() / blocks;
  std::vector<double> leave_out(blocks);
  std::vector<double> rest;
  for (std::size_t b = 0; b < blocks; ++b) {
    rest.clear();
    for (std::size_t i = 0; i < blocks * size; ++i)
      if (i / size != b) rest.push_back(samples[i]);
    leave_out[b] = statistic(rest);
  }
  const double m = mean(leave_out);
  double s = 0.0;
  for (const double v : leave_out) s += (v - m) * (v - m);
  e.error = std::sqrt(static_cast<double>(blocks - 1) / static_cast<double>(blocks) * s);
  return e;
}

namespace {

// Jackknife blocks for the heat capacity: its error is uncertain by about 1/sqrt(2 B).
constexpr std::size_t kMostJackknifeBlocks = 64;

// The error bars of one rung's energies. <U>'s is the blocking estimate with its automatically
// chosen level (analysis/block_average.hpp); the heat capacity's is a jackknife over blocks at
// least as long as the blocks that level found sufficient both for U and for (U - <U>)^2, the
// fluctuation the heat capacity averages (which may stay correlated longer than U).
struct RungErrors {
  BlockAverage energy, fluctuation;
  std::size_t cv_blocks = 0;
};

RungErrors rung_errors(const std::vector<double>& u) {
  RungErrors e;
  e.energy = block_average(u);
  std::vector<double> squares(u.size());
  for (std::size_t i = 0; i < u.size(); ++i)
    squares[i] = (u[i] - e.energy.mean) * (u[i] - e.energy.mean);
  e.fluctuation = block_average(squares);
  const std::size_t length = std::size_t{1} << std::max(e.energy.level, e.fluctuation.level);
  // The blocks jackknife() will use (it takes at most half the samples as blocks); 0: too few
  // samples for an error.
  e.cv_blocks = std::min({kMostJackknifeBlocks, u.size() / length, u.size() / 2});
  if (e.cv_blocks < 2) e.cv_blocks = 0;
  if (u.size() < 2) {  // no fluctuation measured: no correlation time either
    e.energy.correlation_time = kNaN;
    e.fluctuation.correlation_time = kNaN;
  }
  return e;
}

}  // namespace

double heat_capacity(const std::vector<double>& u, double temperature, double kinetic_dof) {
  return 0.5 * kinetic_dof + variance(u) / (temperature * temperature);
}

fs::path write_exchange_results(const ReplicaExchangePlan& plan, const ExchangeState& state,
                                const ExchangeResults& results, double kinetic_dof,
                                const Provenance& provenance) {
  const std::vector<double>& temps = plan.temperatures;
  const std::size_t rungs = temps.size();
  const std::uint64_t skip = plan.settings.equilibration;
  // The samples after the equilibration, per rung.
  std::vector<std::vector<double>> u(rungs);
  for (std::size_t row = 0; row < results.round.size(); ++row) {
    if (results.round[row] <= skip) continue;
    for (std::size_t k = 0; k < rungs; ++k) u[k].push_back(results.energy_at[k][row]);
  }
  nlohmann::json rung_list = nlohmann::json::array(), pair_list = nlohmann::json::array();
  std::string table =
      "rung\ttemperature\tsamples\tU_mean\tU_error\theat_capacity\theat_capacity_error\t"
      "acceptance_up\tpredicted_acceptance_up\n";
  // Acceptance over the same rounds (the equilibration's are in the state's counters only).
  std::vector<std::uint64_t> attempts(rungs, 0), accepted(rungs, 0);
  for (std::size_t row = 0; row < results.round.size(); ++row) {
    if (results.round[row] <= skip) continue;
    for (std::size_t k = 0; k + 1 < rungs; ++k) {
      attempts[k] += results.swaps[row][k] != '-' ? 1 : 0;
      accepted[k] += results.swaps[row][k] == '1' ? 1 : 0;
    }
  }
  std::vector<double> rate(rungs, kNaN), predicted(rungs, kNaN);
  for (std::size_t k = 0; k + 1 < rungs; ++k) {
    if (attempts[k] > 0)
      rate[k] = static_cast<double>(accepted[k]) / static_cast<double>(attempts[k]);
    predicted[k] = predicted_acceptance(1.0 / temps[k], 1.0 / temps[k + 1], u[k], u[k + 1]);
    pair_list.push_back(
        {{"rungs", {k, k + 1}},
         {"temperatures", {temps[k], temps[k + 1]}},
         {"attempts", attempts[k]},
         {"accepted", accepted[k]},
         {"rate", finite_or_null(rate[k])},
         {"predicted_rate", finite_or_null(predicted[k])},
         {"all_rounds", {{"attempts", state.attempts[k]}, {"accepted", state.accepted[k]}}}});
  }
  for (std::size_t k = 0; k < rungs; ++k) {
    const double t = temps[k];
    const RungErrors errors = rung_errors(u[k]);
    const Estimate cv = jackknife(
        u[k], [&](const std::vector<double>& x) { return heat_capacity(x, t, kinetic_dof); },
        errors.cv_blocks);
    const Estimate energy{u[k].empty() ? kNaN : errors.energy.mean,
                          u[k].size() >= 2 ? errors.energy.stderr_ : kNaN};
    const bool reliable = errors.energy.reliable && errors.fluctuation.reliable;
    rung_list.push_back(
        {{"rung", k},
         {"temperature", t},
         {"samples", u[k].size()},
         {"potential_energy",
          {{"mean", finite_or_null(energy.value)},
           {"stderr", finite_or_null(energy.error)},
           {"correlation_rounds", finite_or_null(errors.energy.correlation_time)}}},
         {"heat_capacity",
          {{"mean", finite_or_null(cv.value)},
           {"stderr", finite_or_null(cv.error)},
           {"blocks", errors.cv_blocks},
           {"correlation_rounds", finite_or_null(errors.fluctuation.correlation_time)}}},
         {"errors_reliable", reliable}});
    table += fmt::format("{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\n", k, t, u[k].size(),
                         tsv_number(energy.value), tsv_number(energy.error), tsv_number(cv.value),
                         tsv_number(cv.error), tsv_number(rate[k]), tsv_number(predicted[k]));
  }
  nlohmann::json replicas = nlohmann::json::array();
  const std::vector<std::uint32_t> rung = state.rung_of();
  for (std::size_t r = 0; r < rungs; ++r) {
    replicas.push_back({{"replica", r}, {"rung", rung[r]}, {"round_trips", state.round_trips[r]}});
  }
  const ReplicaExchangeSettings& s = plan.settings;
  nlohmann::json summary = {{"provenance", to_json(provenance)},
                            {"replica_exchange",
                             {{"config", s.config.string()},
                              {"set", s.overrides},
                              {"temperatures", temps},
                              {"interval", s.interval},
                              {"rounds", state.round},
                              {"equilibration_rounds", skip},
                              {"time", static_cast<double>(state.round) * s.interval},
                              {"kinetic_degrees_of_freedom", kinetic_dof},
                              {"round_trips",
                               [&] {
                                 std::uint64_t n = 0;
                                 for (const std::uint64_t t : state.round_trips) n += t;
                                 return n;
                               }()}}},
                            {"rungs", rung_list},
                            {"pairs", pair_list},
                            {"replicas", replicas}};
  write_text_atomically(s.directory / "temperatures.tsv", table);
  const fs::path path = s.directory / "summary.json";
  write_text_atomically(path, summary.dump(2) + "\n");
  return path;
}

}  // namespace kairos

#include "replica/exchange_rule.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include "core/error.hpp"
#include "sweep/sweep_grid.hpp"

namespace kairos {

double exchange_acceptance(double beta_k, double beta_l, double u_k, double u_l) {
  const double exponent = (beta_k - beta_l) * (u_k - u_l);
  return exponent >= 0.0 ? 1.0 : std::exp(exponent);
}

ExchangeState ExchangeState::start(std::size_t rungs, std::uint64_t seed) {
  ExchangeState s;
  s.replica_at.resize(rungs);
  for (std::size_t k = 0; k < rungs; ++k) s.replica_at[k] = static_cast<std::uint32_t>(k);
  s.attempts.assign(rungs > 0 ? rungs - 1 : 0, 0);
  s.accepted.assign(s.attempts.size(), 0);
  s.last_end.assign(rungs, -1);
  if (rungs > 0) s.last_end[0] = 0;  // replica 0 starts on the coldest rung
  s.round_trips.assign(rungs, 0);
  // Its own stream, apart from the replicas' (seeded from system.seed + r).
  std::seed_seq seq{seed, std::uint64_t{0x7265706c696361}};  // "replica"
  s.rng.seed(seq);
  return s;
}

std::vector<std::uint32_t> ExchangeState::rung_of() const {
  std::vector<std::uint32_t> rung(replica_at.size());
  for (std::size_t k = 0; k < replica_at.size(); ++k)
    rung[replica_at[k]] = static_cast<std::uint32_t>(k);
  return rung;
}

std::string attempt_exchanges(ExchangeState& state, const std::vector<double>& temperatures,
                              const std::vector<double>& energy_at) {
  const std::size_t rungs = state.rungs();
  std::string outcome(rungs > 0 ? rungs - 1 : 0, '-');
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (std::size_t k = state.round % 2; k + 1 < rungs; k += 2) {
    const double u = uniform(state.rng);
    ++state.attempts[k];
    const double p = exchange_acceptance(1.0 / temperatures[k], 1.0 / temperatures[k + 1],
                                         energy_at[k], energy_at[k + 1]);
    outcome[k] = '0';
    if (u < p) {
      outcome[k] = '1';
      ++state.accepted[k];
      std::swap(state.replica_at[k], state.replica_at[k + 1]);
    }
  }
  // Round trips: a replica that reaches the coldest rung having gone from it to the hottest
  // (a replica that starts hot has been nowhere yet).
  if (rungs >= 2) {
    const std::uint32_t cold = state.replica_at.front(), hot = state.replica_at.back();
    if (state.last_end[cold] == 1) ++state.round_trips[cold];
    state.last_end[cold] = 0;
    if (state.last_end[hot] == 0) state.last_end[hot] = 1;
  }
  ++state.round;
  return outcome;
}

std::vector<double> parse_temperature_ladder(const std::string& spec, const std::string& what) {
  // The sweep's value forms; its messages name the argument as `what KEY=VALUES`.
  const SweepAxis axis = [&] {
    try {
      return parse_sweep_axis("temperature=" + spec, what);
    } catch (const InputError& e) {
      std::string message = e.what();
      const std::string key = what + " temperature=";
      if (message.starts_with(key)) message.replace(0, key.size(), what + " ");
      throw InputError(message);
    }
  }();
  std::vector<double> ladder;
  for (const std::string& v : axis.values) {
    double t = 0.0;
    const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), t);
    if (ec != std::errc() || end != v.data() + v.size() || !std::isfinite(t) || !(t > 0.0)) {
      throw InputError(
          fmt::format("{} {}: the temperature {} is not a finite number > 0", what, spec, v));
    }
    if (!ladder.empty() && !(t > ladder.back())) {
      throw InputError(fmt::format("{} {}: the temperatures must ascend ({} after {})", what, spec,
                                   v, ladder.back()));
    }
    ladder.push_back(t);
  }
  if (ladder.size() < 2) {
    throw InputError(
        fmt::format("{} {}: replica exchange needs at least two temperatures", what, spec));
  }
  return ladder;
}

double predicted_acceptance(double beta_k, double beta_l, const std::vector<double>& u_k,
                            const std::vector<double>& u_l, std::size_t most) {
  auto thinned = [most](const std::vector<double>& u) {
    const std::size_t stride = std::max<std::size_t>(1, (u.size() + most - 1) / most);
    std::vector<double> out;
    for (std::size_t i = 0; i < u.size(); i += stride) out.push_back(u[i]);
    return out;
  };
  const std::vector<double> a = thinned(u_k), b = thinned(u_l);
  if (a.empty() || b.empty()) return std::numeric_limits<double>::quiet_NaN();
  double sum = 0.0;
  for (const double x : a)
    for (const double y : b) sum += exchange_acceptance(beta_k, beta_l, x, y);
  return sum / (static_cast<double>(a.size()) * static_cast<double>(b.size()));
}

}  // namespace kairos

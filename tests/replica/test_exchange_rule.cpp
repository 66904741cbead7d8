// The replica-exchange rule (replica/exchange_rule.hpp) and its statistics
// (replica/exchange_statistics.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>

#include "core/error.hpp"
#include "replica/exchange_rule.hpp"
#include "replica/exchange_statistics.hpp"

namespace kairos {
namespace {

TEST(ExchangeRule, MetropolisAcceptance) {
  // The colder rung (beta 2) taking the lower energy is always accepted.
  EXPECT_EQ(exchange_acceptance(2.0, 1.0, -1.0, -3.0), 1.0);
  // ...the opposite with exp((2 - 1) (-3 - -1)) = exp(-2).
  EXPECT_DOUBLE_EQ(exchange_acceptance(2.0, 1.0, -3.0, -1.0), std::exp(-2.0));
  EXPECT_EQ(exchange_acceptance(1.0, 1.0, 5.0, -5.0), 1.0);  // one temperature: always
  // The rule is symmetric in the pair: (k, l) and (l, k) give the same probability.
  EXPECT_DOUBLE_EQ(exchange_acceptance(0.5, 2.0, 1.0, 4.0),
                   exchange_acceptance(2.0, 0.5, 4.0, 1.0));
}

TEST(ExchangeRule, RoundsAlternateEvenAndOddPairs) {
  ExchangeState s = ExchangeState::start(5, 1);
  const std::vector<double> t = {1.0, 2.0, 3.0, 4.0, 5.0};
  const std::vector<double> equal(5, 0.0);  // equal energies: every attempt is accepted
  EXPECT_EQ(attempt_exchanges(s, t, equal), "1-1-");
  EXPECT_EQ(s.replica_at, (std::vector<std::uint32_t>{1, 0, 3, 2, 4}));
  EXPECT_EQ(attempt_exchanges(s, t, equal), "-1-1");
  EXPECT_EQ(s.replica_at, (std::vector<std::uint32_t>{1, 3, 0, 4, 2}));
  EXPECT_EQ(s.round, 2u);
  EXPECT_EQ(s.attempts, (std::vector<std::uint64_t>{1, 1, 1, 1}));
  EXPECT_EQ(s.accepted, s.attempts);
  EXPECT_EQ(s.rung_of(), (std::vector<std::uint32_t>{2, 0, 4, 1, 3}));
  // A cold rung far lower in energy than the hot one: never swapped.
  const std::vector<double> split = {-1e6, 0.0, -1e6, 0.0, 0.0};
  EXPECT_EQ(attempt_exchanges(s, t, split), "0-0-");
  EXPECT_EQ(s.replica_at, (std::vector<std::uint32_t>{1, 3, 0, 4, 2}));
}

TEST(ExchangeRule, AcceptedAtTheMetropolisRate) {
  ExchangeState s = ExchangeState::start(2, 42);
  const std::vector<double> t = {0.5, 1.0};  // betas 2 and 1
  const std::vector<double> u = {0.0, 1.0};  // exp((2 - 1) (0 - 1)) = exp(-1)
  const int rounds = 40000;                  // attempts on even rounds only
  for (int r = 0; r < rounds; ++r) {
    // The energies follow the rungs, not the replicas: the rate is that of one fixed pair.
    attempt_exchanges(s, t, u);
  }
  const double p = std::exp(-1.0);
  const double n = static_cast<double>(s.attempts[0]);
  EXPECT_EQ(s.attempts[0], static_cast<std::uint64_t>(rounds / 2));
  EXPECT_NEAR(static_cast<double>(s.accepted[0]) / n, p, 4.0 * std::sqrt(p * (1 - p) / n));
}

TEST(ExchangeRule, TheSameSeedDrawsTheSameDecisions) {
  const std::vector<double> t = {1.0, 1.5, 2.0};
  const std::vector<double> u = {-3.0, -1.0, 0.0};
  ExchangeState a = ExchangeState::start(3, 9), b = ExchangeState::start(3, 9);
  ExchangeState c = ExchangeState::start(3, 10);
  std::string da, db, dc;
  for (int r = 0; r < 200; ++r) {
    da += attempt_exchanges(a, t, u);
    db += attempt_exchanges(b, t, u);
    dc += attempt_exchanges(c, t, u);
  }
  EXPECT_EQ(da, db);
  EXPECT_NE(da, dc);
}

TEST(ExchangeRule, CountsRoundTripsThroughTheLadder) {
  // Two rungs swapped every other round (pair 0 is attempted on even rounds): replica 0 goes
  // cold -> hot (round 0) -> cold (round 2) -> hot -> cold (round 6): two round trips.
  ExchangeState s = ExchangeState::start(2, 1);
  const std::vector<double> t = {1.0, 2.0}, u = {0.0, 0.0};
  for (int r = 0; r < 7; ++r) attempt_exchanges(s, t, u);
  EXPECT_EQ(s.replica_at.front(), 0u);
  EXPECT_EQ(s.round_trips[0], 2u);
  // Replica 1 went hot -> cold -> hot -> cold -> hot: it reached the cold end after the hot
  // end once (round 4), the first time it was at the cold end not counting.
  EXPECT_EQ(s.round_trips[1], 1u);
}

TEST(ExchangeRule, ARoundTripStartsOnTheColdestRung) {
  // Three rungs, every attempt accepted: the replicas cycle through the ladder. Replica 2 starts
  // on the hottest rung: its first way down is no round trip.
  ExchangeState s = ExchangeState::start(3, 1);
  const std::vector<double> t = {1.0, 2.0, 3.0}, u = {0.0, 0.0, 0.0};
  const std::vector<std::vector<std::uint32_t>> expected = {
      {1, 0, 2}, {1, 2, 0}, {2, 1, 0}, {2, 0, 1}, {0, 2, 1}, {0, 1, 2}, {1, 0, 2}};
  for (const auto& after : expected) {
    attempt_exchanges(s, t, u);
    ASSERT_EQ(s.replica_at, after);
  }
  // Replica 0: cold (start) -> hot (round 1) -> cold (round 4); replica 1: cold (round 0) ->
  // hot (round 3) -> cold (round 6); replica 2: hot, then cold (round 2), not hot again yet.
  EXPECT_EQ(s.round_trips, (std::vector<std::uint64_t>{1, 1, 0}));
}

TEST(ExchangeRule, ParsesLadders) {
  const std::vector<double> geometric = parse_temperature_ladder("1:8:4:log", "--temperatures");
  ASSERT_EQ(geometric.size(), 4u);
  EXPECT_DOUBLE_EQ(geometric[1], 2.0);
  EXPECT_DOUBLE_EQ(geometric[2], 4.0);
  EXPECT_EQ(geometric[3], 8.0);
  EXPECT_EQ(parse_temperature_ladder("0.5,1,2", "--temperatures"),
            (std::vector<double>{0.5, 1.0, 2.0}));
  EXPECT_EQ(parse_temperature_ladder("1:2:3", "--temperatures"),
            (std::vector<double>{1.0, 1.5, 2.0}));
  for (const char* bad : {"1", "2,1", "1,1", "-1:2:3", "1:2:3:cubic", "1,x", "1,inf"}) {
    try {
      (void)parse_temperature_ladder(bad, "--temperatures");
      ADD_FAILURE() << bad << " was accepted";
    } catch (const InputError& e) {
      // Named as given on the command line.
      EXPECT_EQ(std::string(e.what()).rfind(std::string("--temperatures ") + bad + ":", 0), 0u)
          << e.what();
    }
  }
}

TEST(ExchangeStatistics, JackknifeOfTheMeanIsTheBlockMeansStandardError) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g;
  std::vector<double> x(1000);
  for (double& v : x) v = g(rng);
  auto mean = [](const std::vector<double>& v) {
    return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  };
  const Estimate e = jackknife(x, mean, 10);
  // For the mean the jackknife over 10 blocks is exactly the standard error of the 10 block
  // means.
  std::vector<double> blocks(10);
  for (int b = 0; b < 10; ++b)
    blocks[b] = mean(std::vector<double>(x.begin() + 100 * b, x.begin() + 100 * (b + 1)));
  const double m = mean(blocks);
  double s = 0.0;
  for (const double v : blocks) s += (v - m) * (v - m);
  EXPECT_NEAR(e.error, std::sqrt(s / 9.0 / 10.0), 1e-12);
  EXPECT_DOUBLE_EQ(e.value, mean(x));
  EXPECT_TRUE(std::isnan(jackknife({1.0, 2.0, 3.0}, mean).error));  // too few for two blocks
}

TEST(ExchangeStatistics, HeatCapacityAndPredictedAcceptance) {
  // U = 0 or -2 with equal weight: var(U) = 1; at T = 0.5 the fluctuation gives 1 / 0.25 = 4.
  EXPECT_DOUBLE_EQ(heat_capacity({0.0, -2.0, 0.0, -2.0}, 0.5, 6.0), 3.0 + 4.0);
  // Two single energies: the prediction is the rule itself.
  EXPECT_DOUBLE_EQ(predicted_acceptance(1.0, 0.5, {0.0}, {1.0}), std::exp(-0.5));
  // The mean over all pairs of samples.
  EXPECT_DOUBLE_EQ(predicted_acceptance(1.0, 0.5, {0.0, 1.0}, {1.0}), 0.5 * (std::exp(-0.5) + 1.0));
}

}  // namespace
}  // namespace kairos

// The thermal conductivity of a mixture (analysis/helfand_transport.hpp) on synthetic moments
// of known statistics: an energy moment G_e = W + h_1 G_1 + h_2 G_2 built of independent random
// walks, whose part correlated with the mass moments G_a must be removed (lambda = the rate of
// W alone, beta = h), whatever the scale of the mass moments and whatever multiple of G_a is
// added to G_e (a change of the species' energy zero changes nothing measurable).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "analysis/helfand_transport.hpp"

namespace kairos {
namespace {

constexpr int kD = 3;
using Transport = HelfandTransport<kD>;

struct Walks {
  double dt = 0.1;
  int samples = 40000;
  double rate_w = 0.7, rate_1 = 2.0, rate_2 = 1.3;  // <dx^2> = 2 rate t per component
  double h1 = 1.8, h2 = -0.9;                       // G_e's parts along G_1 and G_2
  double mix = 0.5;                                 // G_2 = mix G_1 + its own walk
};

// Feeds `transport` with moments from the walks (kT = 1 exactly; V = 1), G_e offset by
// `shift` G_1. Two mass moments if `two`, one otherwise (h2 then unused).
void feed(Transport& transport, const Walks& w, bool two, double shift, std::uint64_t seed) {
  constexpr std::size_t particles = 100;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Vec<kD> W{}, G1{}, G2own{};
  for (int k = 0; k < w.samples; ++k) {
    const double t = k * w.dt;
    Transport::Moments m;
    m.kinetic_trace = kD * (particles - 1.0) * t;  // kT = 1
    const Vec<kD> G2 = w.mix * G1 + G2own;
    for (int a = 0; a < kD; ++a) {
      m.energy[a] = W[a] + (w.h1 + shift) * G1[a] + (two ? w.h2 * G2[a] : 0.0);
    }
    m.mass.push_back(G1);
    if (two) m.mass.push_back(G2);
    transport.add(t, m);
    for (int a = 0; a < kD; ++a) {
      W[a] += std::sqrt(2.0 * w.rate_w * w.dt) * normal(rng);
      G1[a] += std::sqrt(2.0 * w.rate_1 * w.dt) * normal(rng);
      G2own[a] += std::sqrt(2.0 * w.rate_2 * w.dt) * normal(rng);
    }
  }
}

TEST(MixtureConductivity, RemovesThePartOfTheEnergyMomentThatInterdiffusionCarries) {
  const Walks w;
  for (const bool two : {false, true}) {
    SCOPED_TRACE(two ? "two mass moments" : "one mass moment");
    // A scale far from 1: the sums of moments must still resolve the cross correlations.
    Transport t(w.dt, 100, 1.0, two ? 2 : 1, 37.0);
    feed(t, w, two, 0.0, 5);
    ASSERT_NEAR(t.temperature(), 1.0, 1e-12);
    const double from = 1.0, to = 20.0;
    const auto eh = t.einstein_helfand(from, to);
    ASSERT_TRUE(eh[Transport::kHeatGroup]);
    const auto& heat = *eh[Transport::kHeatGroup];
    const double lambda = heat.coefficient / t.scale(Transport::kHeatGroup);
    const double err = heat.stderr_ / t.scale(Transport::kHeatGroup);
    EXPECT_GT(heat.epochs, 7);
    EXPECT_LT(err, 0.1 * w.rate_w);
    EXPECT_NEAR(lambda, w.rate_w, 4.0 * err);
    // Without the projection the energy moment's slope is several times larger.
    const double unprojected = w.rate_w + w.h1 * w.h1 * w.rate_1 +
                               (two ? w.h2 * w.h2 * (w.mix * w.mix * w.rate_1 + w.rate_2) +
                                          2.0 * w.h1 * w.h2 * w.mix * w.rate_1
                                    : 0.0);
    const auto p = t.heat_projection(from, to);
    ASSERT_TRUE(p);
    ASSERT_EQ(p->beta.size(), two ? 2u : 1u);
    EXPECT_NEAR(p->beta[0], w.h1, 0.05 * std::abs(w.h1));
    if (two) {
      EXPECT_NEAR(p->beta[1], w.h2, 0.05 * std::abs(w.h2));
    }
    EXPECT_NEAR(p->removed, 1.0 - w.rate_w / unprojected, 0.03);
    // Green-Kubo of the projected flux, from the same samples.
    const auto gk = t.green_kubo(from, to)[Transport::kHeatGroup];
    ASSERT_TRUE(gk);
    EXPECT_NEAR(gk->coefficient, heat.coefficient,
                3.0 * std::hypot(heat.stderr_, gk->stderr_) + 0.05 * heat.coefficient);
    // The running coefficient of helfand.tsv reaches the fitted value on the window.
    const auto rows = t.helfand_rows(from, to);
    ASSERT_FALSE(rows.empty());
    for (const auto& r : rows) {
      if (r.lag >= from && r.lag <= to) {
        EXPECT_NEAR(r.coefficient[Transport::kHeatGroup] / lambda, 1.0, 0.25) << r.lag;
      }
    }
  }
}

TEST(MixtureConductivity, DoesNotDependOnTheSpeciesEnergyZero) {
  const Walks w;
  const double from = 1.0, to = 20.0;
  Transport a(w.dt, 100, 1.0, 2, 1.0), b(w.dt, 100, 1.0, 2, 1.0);
  feed(a, w, true, 0.0, 9);
  feed(b, w, true, 25.0, 9);  // G_e + 25 G_1: the same walks
  const auto la = a.einstein_helfand(from, to)[Transport::kHeatGroup];
  const auto lb = b.einstein_helfand(from, to)[Transport::kHeatGroup];
  ASSERT_TRUE(la && lb);
  EXPECT_NEAR(lb->coefficient / la->coefficient, 1.0, 1e-6);
  EXPECT_NEAR(lb->stderr_ / la->stderr_, 1.0, 1e-4);
  EXPECT_NEAR(b.heat_projection(from, to)->beta[0] - a.heat_projection(from, to)->beta[0], 25.0,
              1e-6);
}

TEST(MixtureConductivity, OneSpeciesIsTheEnergyMomentAlone) {
  const Walks w;
  Transport t(w.dt, 100, 1.0);
  Walks plain = w;
  plain.h1 = 0.0;
  // Without mass moments the heat moment is G_e itself.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  Vec<kD> W{};
  for (int k = 0; k < plain.samples; ++k) {
    Transport::Moments m;
    m.kinetic_trace = kD * 99.0 * k * plain.dt;
    m.energy = W;
    t.add(k * plain.dt, m);
    for (int a = 0; a < kD; ++a) W[a] += std::sqrt(2.0 * plain.rate_w * plain.dt) * normal(rng);
  }
  const auto heat = t.einstein_helfand(1.0, 20.0)[Transport::kHeatGroup];
  ASSERT_TRUE(heat);
  EXPECT_NEAR(heat->coefficient, plain.rate_w, 4.0 * heat->stderr_);
  const auto p = t.heat_projection(1.0, 20.0);
  ASSERT_TRUE(p);
  EXPECT_TRUE(p->beta.empty());
  EXPECT_EQ(p->removed, 0.0);
}

TEST(MixtureConductivity, RefusesTheWrongNumberOfMassMoments) {
  Transport t(0.1, 100, 1.0, 2, 1.0);
  Transport::Moments m;
  m.mass.resize(1);
  EXPECT_THROW(t.add(0.0, m), std::invalid_argument);
}

}  // namespace
}  // namespace kairos

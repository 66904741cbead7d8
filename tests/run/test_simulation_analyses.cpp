// The analyses on a Simulation held in memory (run/simulation_analyses.hpp, the Python module's
// Simulation.msd, .transport, .rdf, ...) give summary.json's numbers: the same D and transport
// coefficients bit for bit when sampled at the same times, the same contact value and S(0) for
// one sample. The Python module's own tests (tests/python/api_python_analyses.py) check the
// arrays; these run the C++ under the sanitizers too.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/stop_flag.hpp"
#include "io/config.hpp"
#include "io/config_obstacles.hpp"
#include "run/outputs/transport_output.hpp"
#include "run/run.hpp"
#include "run/simulation.hpp"
#include "run/simulation_analyses.hpp"

namespace kairos {
namespace {

namespace fs = std::filesystem;

std::string gas(const std::string& analysis, double time = 5.0) {
  return fmt::format(
      "[system]\nparticles = 100\npacking_fraction = 0.1\nlattice = \"random\"\nseed = 3\n"
      "[run]\nequilibration_time = 0.0\ntime = {}\n"
      "[output]\nprogress = \"never\"\ntrajectory = false\n"
      "[analysis]\n{}",
      time, analysis);
}

nlohmann::json run_cli(const std::string& text, const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("kairos_simulation_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(dir);
  clear_stop_request();
  Config config = parse_config(text, "<test>");
  config.output.directory = dir.string();
  const RunOutcome outcome = run_simulation(config);
  fs::remove_all(dir);
  EXPECT_TRUE(outcome.error.empty()) << outcome.error;
  return outcome.summary;
}

// A mixture's mass moments (run/outputs/transport_output.hpp) are the components' sums
// sum_{i in a} m_i x_i - (M_a / M) sum_i m_i x_i of the unwrapped positions, for every
// component present but the last, whichever species has no particle.
TEST(SimulationAnalyses, MassMomentsAreTheComponentsMassSumsAboutTheCentreOfMass) {
  const std::string text =
      "[system]\nparticles = 100\npacking_fraction = 0.1\nlattice = \"random\"\nseed = 3\n"
      "[[system.species]]\nname = \"A\"\nfraction = 0.5\n"
      "[[system.species]]\nname = \"B\"\nfraction = 0.3\nmass = 3.0\n"
      "[[system.species]]\nname = \"C\"\nfraction = 0.2\nmass = 2.0\ndiameter = 0.8\n"
      "[[system.species]]\nname = \"E\"\nfraction = 0.001\n"
      "[run]\nequilibration_time = 0.0\ntime = 5.0\n"
      "[output]\nprogress = \"never\"\ntrajectory = false\n";
  Simulation<3> sim(parse_config(text, "<test>"), {}, EngineTracking{.helfand = true});
  ASSERT_TRUE(sim.tracks_images());  // kept for the mixture's mass moments
  const std::vector<std::uint32_t>& species = sim.species();
  ASSERT_EQ(std::count(species.begin(), species.end(), 3u), 0);  // E: none
  ASSERT_TRUE(sim.advance_to_time(2.0));
  MassMoments<3> mass(sim.event_integrator("mass moments"));
  ASSERT_EQ(mass.count(), 2u);  // A and B; C is the last present
  EXPECT_EQ(mass.name(0), "A");
  EXPECT_EQ(mass.name(1), "B");
  EXPECT_TRUE(mass.why().empty());
  for (int round = 0; round < 2; ++round) {
    std::vector<Vec<3>> moments;
    mass.sample(sim.event_integrator("mass moments"), moments);
    const std::vector<Vec<3>> x = sim.unwrapped_positions();
    const std::vector<double>& m = sim.masses();
    Vec<3> all{};
    double total = 0.0, scale = 0.0;
    std::array<Vec<3>, 2> sum{};
    std::array<double, 2> mass_of{};
    for (std::size_t i = 0; i < x.size(); ++i) {
      all = all + m[i] * x[i];
      total += m[i];
      scale = std::max(scale, m[i] * std::sqrt(norm2(x[i])));
      if (species[i] < 2) {
        sum[species[i]] = sum[species[i]] + m[i] * x[i];
        mass_of[species[i]] += m[i];
      }
    }
    for (std::size_t a = 0; a < 2; ++a) {
      const Vec<3> expected = sum[a] - (mass_of[a] / total) * all;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(moments[a][c], expected[c], 1e-12 * scale * 100.0);
    }
    ASSERT_TRUE(sim.advance_to_time(4.0));  // the particles cross faces: the images count
  }
}

TEST(SimulationAnalyses, MsdAndTransportAreTheClisBitForBit) {
  const std::string text =
      gas("msd = true\nmsd_interval = 0.05\nvacf = true\nmsd_fit_from = 0.3\nmsd_fit_to = 1.0\n"
          "transport = true\ntransport_interval = 0.05\ntransport_fit_from = 0.3\n"
          "transport_fit_to = 1.0\n");
  const nlohmann::json summary = run_cli(text, "msd");
  const Config config = parse_config(text, "<test>");
  CorrelationRequest request;
  request.interval = 0.05;
  request.duration = 5.0;
  request.fit_from = 0.3;
  request.fit_to = 1.0;

  Simulation<3> sim(config);
  const MsdMeasurement<3> m = measure_msd(sim, request, true);
  EXPECT_EQ(sim.time(), 5.0);
  const nlohmann::json& d = summary["diffusion"]["species"]["A"];
  ASSERT_TRUE(m.diffusion[0].has_value());
  EXPECT_EQ(m.diffusion[0]->coefficient, d["coefficient"].get<double>());
  EXPECT_EQ(m.diffusion[0]->stderr_, d["coefficient_stderr"].get<double>());
  ASSERT_TRUE(m.green_kubo[0].has_value());
  EXPECT_EQ(m.green_kubo[0]->coefficient, d["green_kubo_coefficient"].get<double>());
  EXPECT_EQ(m.msd->samples(), summary["diffusion"]["samples"].get<std::uint64_t>());

  Simulation<3> helfand(config, {}, EngineTracking{.images = false, .helfand = true});
  const TransportMeasurement<3> t = measure_transport(helfand, request);
  const nlohmann::json& cli = summary["transport"];
  EXPECT_EQ(t.transport->temperature(), cli["temperature"].get<double>());
  const char* names[3] = {"shear_viscosity", "bulk_viscosity", "thermal_conductivity"};
  for (int g = 0; g < 3; ++g) {
    ASSERT_TRUE(t.einstein_helfand[g].has_value()) << names[g];
    EXPECT_EQ(t.einstein_helfand[g]->coefficient / t.transport->scale(g),
              cli[names[g]]["value"].get<double>())
        << names[g];
    ASSERT_TRUE(t.green_kubo[g].has_value()) << names[g];
    EXPECT_EQ(t.green_kubo[g]->coefficient / t.transport->scale(g),
              cli[names[g]]["green_kubo"].get<double>())
        << names[g];
  }
}

TEST(SimulationAnalyses, StructureOfOneSampleIsTheClis) {
  const std::string text =
      gas("rdf = true\nrdf_bins = 40\nstructure_factor = true\nbond_order = true\ninterval = 1.0\n",
          1.0);
  const nlohmann::json summary = run_cli(text, "structure");
  Simulation<3> sim(parse_config(text, "<test>"));
  sim.advance_to_time(1.0);
  const RdfNow<3> g = rdf_now(sim, 40, 0.0);
  const nlohmann::json& rdf = summary["analysis"]["rdf"];
  EXPECT_EQ(rdf["samples"].get<int>(), 1);
  EXPECT_EQ(g.max_distance, rdf["max_distance"].get<double>());
  EXPECT_EQ(g.contact[0], rdf["contact"]["A-A"]["g"].get<double>());
  EXPECT_EQ(g.pairs[0], "A-A");
  const StructureFactorNow s = structure_factor_now(sim, 0.0);
  const nlohmann::json& sk = summary["analysis"]["structure_factor"];
  EXPECT_EQ(s.k_max, sk["k_max"].get<double>());
  EXPECT_EQ(s.s[0], sk["s_k_min"].get<double>());
  const BondOrderValues<3> b = bond_order_now(sim, 1.4, "cutoff");
  EXPECT_EQ(b.global[1], summary["analysis"]["bond_order"]["q6"]["global"].get<double>());
  EXPECT_THROW(bond_order_now(sim, 100.0, "cutoff"), InputError);
  EXPECT_THROW(rdf_now(sim, 40, 1e3), InputError);
}

TEST(SimulationAnalyses, ImagesUnwrapThePositions) {
  Simulation<2> sim(
      parse_config(
          "[system]\ndimension = 2\nparticles = 50\npacking_fraction = 0.05\nlattice = \"random\"\n"
          "[output]\ntrajectory = false\n",
          "<test>"),
      {}, EngineTracking{.images = true});
  ASSERT_TRUE(sim.tracks_images());
  EXPECT_FALSE(sim.tracks_helfand());
  EXPECT_THROW(sim.helfand_moments(), InputError);
  int crossed = 0;
  for (int k = 1; k <= 20; ++k) {
    sim.advance_to_time(0.5 * k);
    const auto x = sim.positions();
    const auto u = sim.unwrapped_positions();
    const auto images = sim.images();
    for (std::size_t i = 0; i < x.size(); ++i) {
      for (int a = 0; a < 2; ++a) {
        EXPECT_NEAR(x[i][a] + images[i][a] * sim.box()[a], u[i][a], 1e-9);
        crossed = std::max(crossed, std::abs(images[i][a]));
      }
    }
  }
  EXPECT_GT(crossed, 0);
  // Without counters (and none asked for by the configuration): refused.
  Simulation<2> bare(parse_config(
      "[system]\ndimension = 2\nparticles = 50\npacking_fraction = 0.05\nlattice = \"random\"\n"
      "[output]\ntrajectory = false\n",
      "<test>"));
  EXPECT_FALSE(bare.tracks_images());
  EXPECT_THROW(bare.unwrapped_positions(), InputError);
}

TEST(SimulationAnalyses, HelfandMomentsAreRefusedWhereTransportIs) {
  const Config inelastic = parse_config(
      "[system]\nparticles = 50\npacking_fraction = 0.1\nlattice = \"random\"\n"
      "[contact]\nrestitution = 0.9\n",
      "<test>");
  try {
    Simulation<3> sim(inelastic, {}, EngineTracking{.helfand = true});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("contact.restitution"), std::string::npos) << e.what();
  }
  ASSERT_TRUE(transport_obstacle(inelastic).has_value());
  EXPECT_EQ(transport_obstacle(inelastic)->key, "contact.restitution");
}

}  // namespace
}  // namespace kairos

// The worked example of docs/extending.md ("Adding an output or analysis"), as it stands there:
// an observer that writes the time and the kinetic energy at every thermo interval, run under
// both integrators. Keep the two in step.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "core/stop_flag.hpp"
#include "io/config.hpp"
#include "io/line_file.hpp"
#include "run/outputs/observer.hpp"
#include "run/run_driver.hpp"

namespace kairos {
namespace {

// ---- src/run/outputs/energy_log.hpp of the example
template <int D>
class EnergyLog final : public Observer<D> {
 public:
  static constexpr std::array<std::string_view, 1> kFiles{"energy.tsv"};
  std::string name() const override { return std::string(kFiles[0]); }
  // The thermo interval (a key of its own would be declared in io/config).
  double interval(const Config& config, double production) const override {
    return config.output.thermo_interval > 0 ? config.output.thermo_interval : production / 100.0;
  }
  void open(const RunContext<D>& run) override;
  void write(const RunContext<D>& run) override;

 private:
  std::optional<LineFile> file_;
};

// ---- src/run/outputs/energy_log.cpp of the example
template <int D>
void EnergyLog<D>::open(const RunContext<D>& run) {
  const std::filesystem::path path = run.directory() / name();
  const std::string header = "time\tkinetic_energy\n";
  // A continued run appends (see "What is awkward" for what that leaves after kill -9).
  file_.emplace(run.restarted() ? LineFile(path, header) : LineFile::create(path, header));
}

template <int D>
void EnergyLog<D>::write(const RunContext<D>& run) {
  const Integrator<D>& integrator = run.integrator();
  file_->append(fmt::format("{:.17g}\t{:.17g}\n", integrator.time(), integrator.kinetic_energy()));
}

// ---- the test
namespace fs = std::filesystem;

class ExtendingExample : public ::testing::TestWithParam<const char*> {};

TEST_P(ExtendingExample, TheEnergyLogHasALinePerThermoIntervalUnderEitherIntegrator) {
  const fs::path dir = fs::temp_directory_path() /
                       ("kairos_extending_" + std::to_string(::getpid()) + "_" + GetParam());
  fs::remove_all(dir);
  clear_stop_request();
  std::string text =
      "[system]\nparticles = 256\npacking_fraction = 0.3\n[run]\nintegrator = \"" +
      std::string(GetParam()) +
      "\"\nequilibration_collisions_per_particle = 1.0\ncollisions_per_particle = 2.0\n"
      "[output]\nprogress = \"never\"\nthermo_interval = 0.5\ndirectory = \"" +
      dir.string() + "\"\n";
  if (std::string(GetParam()) == "dem")
    text += "[soft]\nmodel = \"dashpot\"\nstiffness = 10000.0\nrestitution = 0.9\n";
  RunDriver<3> driver(parse_config(text, "<test>"), std::nullopt, {});
  driver.add_observer(std::make_unique<EnergyLog<3>>());
  const RunOutcome outcome = driver.run();
  ASSERT_TRUE(outcome.error.empty()) << outcome.error;
  std::ifstream in(dir / "energy.tsv");
  std::string line;
  int lines = 0;
  while (std::getline(in, line)) ++lines;
  EXPECT_EQ(lines, 1 + 2 + 4);  // the header, 2 rows of equilibration, 4 of production
  EXPECT_NE(outcome.summary["outputs"].dump().find("energy.tsv"), std::string::npos);
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(BothIntegrators, ExtendingExample, ::testing::Values("event", "dem"));

}  // namespace
}  // namespace kairos

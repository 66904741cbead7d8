// run/outputs/registry's list of output files is every file the outputs and analyses write: a
// run with each of them on writes nothing else into its directory (but config.toml and the
// lock). The directory's guard and --overwrite act on that list (run/output_directory.cpp).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "core/stop_flag.hpp"
#include "io/config.hpp"
#include "run/outputs/registry.hpp"
#include "run/run.hpp"

namespace kairos {
namespace {

namespace fs = std::filesystem;

TEST(OutputFiles, EveryFileARunWritesIsListed) {
  clear_stop_request();
  const fs::path dir =
      fs::temp_directory_path() / ("kairos_output_files_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const std::string text =
      "[system]\nparticles = 500\npacking_fraction = 0.3\nseed = 4\n"
      "species = [{name = \"A\", fraction = 0.5}, {name = \"B\", fraction = 0.5}]\n"
      "[run]\nequilibration_collisions_per_particle = 1.0\ncollisions_per_particle = 20.0\n"
      "[output]\nprogress = \"never\"\nprofile_axis = \"z\"\ndirectory = \"" +
      dir.string() +
      "\"\n"
      "[analysis]\nmsd = true\nvacf = true\nmutual_diffusion = true\ntransport = true\nrdf = true\n"
      "structure_factor = true\nbond_order = true\nvelocity_distribution = true\n"
      "[compress]\npacking_fraction = 0.31\n";
  const RunOutcome outcome = run_simulation(parse_config(text, "<test>"));
  ASSERT_TRUE(outcome.error.empty()) << outcome.error;
  const auto& listed = output_file_names();
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name == "config.toml" || name == ".kairos.lock") continue;
    ++files;
    EXPECT_NE(std::find(listed.begin(), listed.end(), name), listed.end())
        << name << " is written but not in output_file_names()";
  }
  // Every listed file was written by this run (the list holds no name no output writes).
  EXPECT_EQ(files, static_cast<int>(listed.size()));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace kairos

#include "run/run.hpp"

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/gsd_snapshot.hpp"
#include "run/run_driver.hpp"

namespace kairos {

RunOutcome run_simulation(const Config& config,
                          const std::optional<std::filesystem::path>& restart_file,
                          const RunOptions& options) {
  const int dimension = config.system.dimension;
  if (restart_file && std::filesystem::exists(*restart_file)) {
    const int stored = gsd_dimension(*restart_file);
    if (stored != dimension) {
      throw InputError(fmt::format("restart file '{}' holds a {}D state but system.dimension = {}",
                                   restart_file->string(), stored, dimension));
    }
  }
  return dimension == 2 ? RunDriver<2>(config, restart_file, options).run()
                        : RunDriver<3>(config, restart_file, options).run();
}

}  // namespace kairos

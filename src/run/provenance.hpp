// Where a run's outputs came from (summary.json's `provenance`, config.toml's header): the
// program (version and the git commit it was built from), when and on which host it ran, how it
// was invoked and which restart file it continued. Nothing here changes a result: the hash gate
// (scripts/hash_outputs.py) and the restart files leave it out.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace kairos {

struct Provenance {
  std::string version;       // KAIROS_VERSION
  std::string commit;        // the build's git commit ("unknown" outside a git checkout)
  std::string date;          // the run's start, UTC, ISO 8601
  std::string host;          // gethostname()
  std::string command_line;  // as invoked ("" when a library caller gave none)
  std::string restart_file;  // the file it continued ("": a new run)
};

// The provenance of a run starting now.
Provenance provenance_now(const std::string& command_line,
                          const std::optional<std::filesystem::path>& restart_file);

nlohmann::json to_json(const Provenance& p);

// Comment lines for the top of config.toml ("# ..." each, ending in a newline).
std::string toml_comment(const Provenance& p);

// argv as one line a POSIX shell would split back into the same words.
std::string shell_command_line(const std::vector<std::string>& words);

}  // namespace kairos

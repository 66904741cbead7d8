#include "run/output_directory.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "io/gsd_file.hpp"
#include "run/outputs/registry.hpp"

namespace kairos {

namespace fs = std::filesystem;

namespace {

// What a run writes into its directory (config.toml is only a description: not guarded).

std::string holder_of(int fd) {
  char text[32] = {};
  const ssize_t n = ::pread(fd, text, sizeof text - 1, 0);
  const std::string pid = n > 0 ? std::string(text, static_cast<std::size_t>(n)) : "";
  return pid.empty() ? "another run" : "another run (process " + pid + ")";
}

// The run id a file of the directory records: "" if none (an older Kairos) or unreadable.
struct RecordedId {
  std::string file, id;
};
std::vector<RecordedId> recorded_run_ids(const fs::path& dir, const fs::path& restart_file) {
  std::vector<RecordedId> out;
  std::error_code ec;
  const fs::path restart = dir / kRestartFileName;
  // The restart file continued is no evidence of what the directory holds (it may have been
  // copied there).
  if (fs::exists(restart, ec) && !fs::equivalent(restart, restart_file, ec)) {
    std::string id;
    try {
      const gsd::Reader r(restart);
      const std::uint64_t f = r.frame_count() == 0 ? 0 : r.frame_count() - 1;
      if (r.frame_count() > 0 && r.find(f, "kairos/run/id")) {
        const auto text = r.read<std::int8_t>(f, "kairos/run/id");
        id.assign(text.begin(), text.end());
      }
    } catch (const std::exception&) {
      id.clear();  // unreadable: no evidence either way
    }
    out.push_back({std::string(kRestartFileName), id});
  }
  const fs::path summary = dir / kSummaryFileName;
  if (fs::exists(summary, ec)) {
    std::string id;
    try {
      std::ifstream in(summary);
      const nlohmann::json j = nlohmann::json::parse(in);
      if (j.contains("run_id") && j["run_id"].is_string()) id = j["run_id"].get<std::string>();
    } catch (const std::exception&) {
      id.clear();
    }
    out.push_back({std::string(kSummaryFileName), id});
  }
  return out;
}

}  // namespace

void OutputDirectory::release() noexcept {
  if (lock_fd_ >= 0) ::close(lock_fd_);
  lock_fd_ = -1;
}

OutputDirectory::OutputDirectory(const fs::path& dir,
                                 const std::optional<RestartLineage>& continuing, bool overwrite)
    : dir_(dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    throw InputError("output.directory: cannot create '" + dir.string() +
                     "': " + (ec ? ec.message() : std::string("not a directory")));
  }
  const fs::path lock = dir / ".kairos.lock";
  lock_fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
  if (lock_fd_ < 0) {
    throw InputError(fmt::format("output.directory: cannot write into '{}': {}", dir.string(),
                                 std::strerror(errno)));
  }
  if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    const std::string who = holder_of(lock_fd_);
    ::close(lock_fd_);
    lock_fd_ = -1;
    throw InputError(fmt::format(
        "output.directory '{}' is in use by {}: two runs writing one directory would overwrite "
        "each other's files; choose another directory (-o)",
        dir.string(), who));
  }
  const std::string pid = std::to_string(::getpid());
  if (::ftruncate(lock_fd_, 0) != 0 || ::pwrite(lock_fd_, pid.data(), pid.size(), 0) < 0) {
    // The pid only makes the message of a refused second run nicer.
  }
  std::string found;
  for (const std::string& name : output_file_names())
    if (fs::exists(dir / name, ec)) found += (found.empty() ? "" : ", ") + name;
  if (found.empty()) return;
  const auto remove_outputs = [&] {
    for (const std::string& name : output_file_names()) {
      // The restart file being continued stays until the continued run replaces it.
      if (continuing && fs::equivalent(dir / name, continuing->restart_file, ec)) continue;
      fs::remove(dir / name, ec);
      if (ec) {
        release();
        throw InputError(
            fmt::format("cannot remove '{}': {}", (dir / name).string(), ec.message()));
      }
    }
  };
  if (continuing) {
    const RestartLineage& lineage = *continuing;
    const fs::path home =
        lineage.restart_file.has_parent_path() ? lineage.restart_file.parent_path() : ".";
    const bool own_directory = fs::equivalent(home, dir, ec) && !ec;
    std::string other;  // the first file recording another run id
    bool matched = false;
    for (const RecordedId& r : recorded_run_ids(dir, lineage.restart_file)) {
      if (r.id.empty()) continue;
      if (r.id == lineage.run_id) {
        matched = true;
      } else if (other.empty()) {
        other = fmt::format("run id {} in its {}", r.id, r.file);
      }
    }
    // A restart file without a run id (an older Kairos) continues its own directory's outputs.
    if (own_directory && lineage.run_id.empty()) other.clear();
    if (other.empty() && (matched || own_directory)) {
      continues_ = true;
      return;
    }
    if (!overwrite) {
      release();
      const std::string theirs =
          other.empty() ? "a run that records no run id (an older Kairos, or a run killed before "
                          "its first restart file), so they cannot be told to be the same run's"
                        : "another run (" + other + ")";
      const std::string ours = lineage.run_id.empty() ? "records no run id (an older file)"
                                                      : "is of run " + lineage.run_id;
      throw InputError(fmt::format(
          "output.directory '{}' holds outputs ({}) of {}, and restart file '{}' {}: continuing "
          "there would mix two runs' files; continue into the restart file's own directory or an "
          "empty one (-o), or pass --overwrite to replace those outputs (the continued run then "
          "writes them afresh from the restart point)",
          dir.string(), found, theirs, lineage.restart_file.string(), ours));
    }
    remove_outputs();
    return;
  }
  if (!overwrite) {
    const bool restartable = fs::exists(dir / kRestartFileName, ec);
    release();
    throw InputError(fmt::format(
        "output.directory '{}' holds the outputs of an earlier run ({}): {}write this run to "
        "another directory (-o), or pass --overwrite to replace them",
        dir.string(), found,
        restartable
            ? fmt::format("continue it with --restart {}, ", (dir / kRestartFileName).string())
            : ""));
  }
  remove_outputs();
}

OutputDirectory::OutputDirectory(OutputDirectory&& other) noexcept
    : dir_(std::move(other.dir_)),
      lock_fd_(std::exchange(other.lock_fd_, -1)),
      continues_(other.continues_) {}

OutputDirectory::~OutputDirectory() {
  release();  // releases the lock
}

std::string new_run_id() {
  std::random_device device;
  std::string id;
  for (int k = 0; k < 4; ++k) id += fmt::format("{:08x}", static_cast<std::uint32_t>(device()));
  return id;
}

std::string lineage_run_id(const std::optional<std::filesystem::path>& restart_file,
                           const RunProgress& resumed) {
  return restart_file && !resumed.run_id.empty() ? resumed.run_id : new_run_id();
}

OutputContinuation output_continuation(bool continues_outputs, const RunProgress& resumed) {
  OutputContinuation c;
  c.same_directory = continues_outputs;
  if (!c.same_directory) return c;
  if (resumed.thermo_rows >= 0) c.thermo_rows = static_cast<std::uint64_t>(resumed.thermo_rows);
  if (resumed.trajectory_frames >= 0)
    c.trajectory_frames = static_cast<std::uint64_t>(resumed.trajectory_frames);
  return c;
}

}  // namespace kairos

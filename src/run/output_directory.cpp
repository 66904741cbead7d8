#include "run/output_directory.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "core/error.hpp"

namespace kairos {

namespace fs = std::filesystem;

namespace {

// What a run writes into its directory (config.toml is only a description: not guarded).
constexpr std::array<const char*, 5> kOutputs = {"summary.json", "thermo.tsv", "trajectory.gsd",
                                                 "restart.gsd", "profile.tsv"};

std::string holder_of(int fd) {
  char text[32] = {};
  const ssize_t n = ::pread(fd, text, sizeof text - 1, 0);
  const std::string pid = n > 0 ? std::string(text, static_cast<std::size_t>(n)) : "";
  return pid.empty() ? "another run" : "another run (process " + pid + ")";
}

}  // namespace

OutputDirectory::OutputDirectory(const fs::path& dir, bool continuing, bool overwrite) : dir_(dir) {
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
  if (continuing) return;
  std::string found;
  for (const char* name : kOutputs)
    if (fs::exists(dir / name, ec)) found += (found.empty() ? "" : ", ") + std::string(name);
  if (found.empty()) return;
  if (!overwrite) {
    const bool restartable = fs::exists(dir / "restart.gsd", ec);
    ::close(lock_fd_);
    lock_fd_ = -1;
    throw InputError(fmt::format(
        "output.directory '{}' holds the outputs of an earlier run ({}): {}write this run to "
        "another directory (-o), or pass --overwrite to replace them",
        dir.string(), found,
        restartable ? fmt::format("continue it with --restart {}, ", (dir / "restart.gsd").string())
                    : ""));
  }
  for (const char* name : kOutputs) {
    fs::remove(dir / name, ec);
    if (ec)
      throw InputError(fmt::format("cannot remove '{}': {}", (dir / name).string(), ec.message()));
  }
}

OutputDirectory::OutputDirectory(OutputDirectory&& other) noexcept
    : dir_(std::move(other.dir_)), lock_fd_(std::exchange(other.lock_fd_, -1)) {}

OutputDirectory::~OutputDirectory() {
  if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the lock
}

}  // namespace kairos

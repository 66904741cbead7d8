#include "io/log_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace kairos {

std::string utc_time(std::time_t at) {
  std::tm utc{};
  gmtime_r(&at, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

LogFile::~LogFile() {
  if (fd_ >= 0) ::close(fd_);
}

bool LogFile::open(const std::filesystem::path& path) {
  if (fd_ >= 0) ::close(fd_);
  path_ = path;
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ >= 0) return true;
  std::fprintf(stderr, "kairos: warning: cannot open %s: %s; going on without this log\n",
               path.c_str(), std::strerror(errno));
  return false;
}

void LogFile::line_at(std::time_t at, std::string_view text) {
  if (fd_ < 0) return;
  stamped(utc_time(at) + " " + std::string(text));
}

void LogFile::stamped(std::string_view text) {
  if (fd_ < 0) return;
  const std::string whole = std::string(text) + "\n";
  const ssize_t written = ::write(fd_, whole.data(), whole.size());
  if (written == static_cast<ssize_t>(whole.size())) return;
  std::fprintf(stderr, "kairos: warning: cannot write %s: %s; no further log lines\n",
               path_.c_str(), written < 0 ? std::strerror(errno) : "short write");
  ::close(fd_);
  fd_ = -1;
}

}  // namespace kairos

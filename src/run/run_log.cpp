#include "run/run_log.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>

#include <fmt/format.h>

namespace kairos {

namespace {

// The wall-clock time of a line: UTC, ISO 8601, to the second.
std::string utc(std::time_t at) {
  std::tm utc{};
  gmtime_r(&at, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

std::string utc_now() {
  return utc(std::time(nullptr));
}

}  // namespace

RunLog::RunLog(double interval_seconds, bool echo)
    : interval_(interval_seconds > 0.0 ? interval_seconds : 0.0),
      echo_(echo),
      created_(std::time(nullptr)) {}

RunLog::~RunLog() {
  if (fd_ >= 0) ::close(fd_);
}

void RunLog::note(const std::string& text) {
  if (!enabled()) return;
  noted_.push_back(utc_now() + " " + text);
  echo(text);
}

void RunLog::echo(const std::string& text) const {
  if (!echo_) return;
  std::fprintf(stdout, "%s\n", text.c_str());
  std::fflush(stdout);
}

void RunLog::setup_step(const std::string& step, const std::string& detail) {
  if (!enabled()) return;
  const auto now = Clock::now();
  if (step != step_) {
    step_ = step;
    step_start_ = step_noted_ = now;
    note("setup: " + step);
    return;
  }
  if (std::chrono::duration<double>(now - step_noted_).count() < interval_) return;
  step_noted_ = now;
  note(fmt::format("setup: {}: {}{} so far", step, detail.empty() ? "" : detail + ", ",
                   format_duration(std::chrono::duration<double>(now - step_start_).count())));
}

void RunLog::open(const std::filesystem::path& file, const std::vector<std::string>& header,
                  const std::vector<std::string>& trailer) {
  if (!enabled()) return;
  file_ = file;
  fd_ = ::open(file.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    std::fprintf(stderr, "kairos: warning: cannot open %s: %s; the run goes on without its log\n",
                 file.c_str(), std::strerror(errno));
    interval_ = 0.0;
    return;
  }
  for (const std::string& h : header) write(utc(created_) + " " + h + "\n");
  for (const std::string& n : noted_) write(n + "\n");
  noted_.clear();
  for (const std::string& t : trailer) line(t);
}

void RunLog::progress(const ProgressInfo& info, bool force) {
  if (!enabled()) return;
  const auto now = Clock::now();
  if (clock_.enter(info, now) && !force) return;  // the rate needs an interval
  if (!force && clock_.seconds_since_reading(now) < interval_) return;
  const std::string text = clock_.read(info, now);
  line(text);
  echo(text);
}

void RunLog::line(const std::string& text) {
  if (fd_ < 0) return;
  write(utc_now() + " " + text + "\n");
}

// Whole lines by one write(2) each (O_APPEND: a line is never interleaved or torn by a
// concurrent writer); a short write or an error ends the log.
void RunLog::write(const std::string& text) {
  if (fd_ < 0) return;
  const ssize_t written = ::write(fd_, text.data(), text.size());
  if (written == static_cast<ssize_t>(text.size())) return;
  std::fprintf(stderr, "kairos: warning: cannot write %s: %s; no further log lines\n",
               file_.c_str(), written < 0 ? std::strerror(errno) : "short write");
  ::close(fd_);
  fd_ = -1;
  interval_ = 0.0;
}

}  // namespace kairos

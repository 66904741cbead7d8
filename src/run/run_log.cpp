#include "run/run_log.hpp"

#include <cstdio>
#include <ctime>

#include <fmt/format.h>

namespace kairos {

namespace {

std::string utc_now() {
  return utc_time(std::time(nullptr));
}

}  // namespace

RunLog::RunLog(double interval_seconds, bool echo)
    : interval_(interval_seconds > 0.0 ? interval_seconds : 0.0),
      echo_(echo),
      created_(std::time(nullptr)) {}

RunLog::~RunLog() = default;

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
  if (!file_.open(file)) {
    interval_ = 0.0;  // the run goes on without its log
    return;
  }
  for (const std::string& h : header) write(utc_time(created_) + " " + h);
  for (const std::string& n : noted_) write(n);
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
  if (!file_.is_open()) return;
  write(utc_now() + " " + text);
}

// A failed write ends the log (LogFile) and with it the progress lines.
void RunLog::write(const std::string& stamped_line) {
  file_.stamped(stamped_line);
  if (!file_.is_open()) interval_ = 0.0;
}

}  // namespace kairos

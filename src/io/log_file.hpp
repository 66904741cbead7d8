// A log file beside a command's outputs (run.log, sweep.log, replica-exchange.log): lines
// stamped with the UTC time, appended (a continued command adds to what the earlier ones
// wrote: a log records what happened). Each line goes out in one write(2) with O_APPEND, so
// that lines of several writers (a sweep's MPI ranks) are never interleaved or torn. A log
// never stops the work it describes: a file that cannot be opened or written is reported once
// on stderr and the log ends there.
#pragma once

#include <ctime>
#include <filesystem>
#include <string>
#include <string_view>

namespace kairos {

// UTC, ISO 8601, to the second: 2026-12-07T21:33:07Z.
std::string utc_time(std::time_t at);

class LogFile {
 public:
  LogFile() = default;
  LogFile(const LogFile&) = delete;
  LogFile& operator=(const LogFile&) = delete;
  ~LogFile();

  // Opens (appends to) `path`; false after a warning on stderr naming it when it cannot.
  bool open(const std::filesystem::path& path);
  bool is_open() const { return fd_ >= 0; }
  // `text` stamped with the time now (or `at`), as one line.
  void line(std::string_view text) { line_at(std::time(nullptr), text); }
  void line_at(std::time_t at, std::string_view text);
  // A line stamped already.
  void stamped(std::string_view text);

 private:
  int fd_ = -1;
  std::filesystem::path path_;
};

}  // namespace kairos

// run.log in the output directory (output.log_interval): what a batch run did, for a reader
// without its terminal, as LAMMPS's log.lammps. A header (start, program, command line, the
// restart file continued), the set-up's steps, a progress line every log_interval wall seconds
// (phase, share done, simulated time, event rate, ETA: the progress line's text), and the end
// (why it stopped, wall time, events). Appended to by a run continued in the same directory:
// a log records what happened, so lines of an interrupted part stay. With output.progress =
// "auto" and stderr not a terminal (a batch job) the progress lines go to stdout too.
// Nothing here changes a result; a failed write is reported once on stderr and ends the log,
// not the run.
#pragma once

#include <chrono>
#include <cstdint>
#include <ctime>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "io/log_file.hpp"
#include "io/progress.hpp"

namespace kairos {

class RunLog {
 public:
  static constexpr std::string_view kFile = "run.log";

  // interval_seconds 0: no log (every call does nothing); echo: progress lines on stdout too.
  RunLog(double interval_seconds, bool echo);
  RunLog(const RunLog&) = delete;
  RunLog& operator=(const RunLog&) = delete;
  ~RunLog();

  bool enabled() const { return interval_ > 0.0; }
  // A line before the file exists (the set-up's steps): kept, written at open(); on stdout at
  // once in a batch job.
  void note(const std::string& text);
  // A long set-up step, called as it goes on: noted when it begins, and again (with `detail`,
  // how far it is, and its wall time so far) when log_interval wall seconds have passed since
  // its last note.
  void setup_step(const std::string& step, const std::string& detail = {});
  // Opens (appends to) `file`: the header lines (stamped with the time this log was made, early in
  // the set-up), the noted ones, then the trailer's.
  void open(const std::filesystem::path& file, const std::vector<std::string>& header,
            const std::vector<std::string>& trailer);
  // A progress line, when log_interval wall seconds have passed since the last one (or the
  // phase began); `force`: now (the end of a phase).
  void progress(const ProgressInfo& info, bool force = false);
  // A line now.
  void line(const std::string& text);

 private:
  using Clock = PhaseClock::Clock;
  void write(const std::string& stamped_line);
  void echo(const std::string& text) const;  // on stdout in a batch job

  double interval_ = 0.0;
  bool echo_ = false;
  LogFile file_;
  std::time_t created_;
  std::vector<std::string> noted_;
  std::string step_;
  Clock::time_point step_start_{}, step_noted_{};
  PhaseClock clock_;
};

}  // namespace kairos

#include "sweep/sweep_runner.hpp"

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/stop_flag.hpp"
#include "io/log_file.hpp"
#include "io/progress.hpp"
#include "run/output_directory.hpp"
#include "run/provenance.hpp"
#include "sweep/sweep_results.hpp"

namespace kairos {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Child {
  pid_t pid = -1;
  std::size_t index = 0;
  Clock::time_point start;
  bool signalled = false;  // sent SIGTERM by the sweep's stop
};

void append_line(const fs::path& file, const std::string& line) {
  std::FILE* f = std::fopen(file.c_str(), "a");
  if (f == nullptr) return;  // the attempt's own outputs say more; a console line is optional
  std::fputs((line + "\n").c_str(), f);
  std::fclose(f);
}

// Starts `executable args...` in a process group of its own (a terminal's Ctrl-C reaches the
// sweep, which passes it on once), with stdout and stderr appended to `console` and stdin
// closed. The child gets SIGTERM if the sweep dies. -1 with `error` set if it cannot start.
pid_t spawn_run(const fs::path& executable, const std::vector<std::string>& args,
                const fs::path& console, std::string& error) {
  const int out = ::open(console.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (out < 0) {
    error = fmt::format("{}: cannot open: {}", console.string(), std::strerror(errno));
    return -1;
  }
  const int in = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  std::vector<std::string> words = {executable.string()};
  words.insert(words.end(), args.begin(), args.end());
  const std::string header = fmt::format("kairos sweep: attempt: {}\n", shell_command_line(words));
  if (::write(out, header.data(), header.size()) < 0) {
    error = fmt::format("{}: cannot write: {}", console.string(), std::strerror(errno));
    ::close(out);
    if (in >= 0) ::close(in);
    return -1;
  }
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid == 0) {
    // Only async-signal-safe calls from here to exec.
    ::setpgid(0, 0);
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) ::_exit(128 + SIGTERM);
    if (in >= 0) ::dup2(in, STDIN_FILENO);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(out, STDERR_FILENO);
    std::signal(SIGPIPE, SIG_DFL);
    std::signal(SIGXFSZ, SIG_DFL);
    sigset_t none;
    sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    ::execv(argv[0], argv.data());
    const char* why = std::strerror(errno);
    const char* prefix = "kairos sweep: error: cannot start the run: ";
    (void)!::write(STDERR_FILENO, prefix, std::strlen(prefix));
    (void)!::write(STDERR_FILENO, why, std::strlen(why));
    (void)!::write(STDERR_FILENO, "\n", 1);
    ::_exit(127);
  }
  const int fork_errno = errno;
  ::close(out);
  if (in >= 0) ::close(in);
  if (pid < 0) {
    error = fmt::format("cannot start a process: {}", std::strerror(fork_errno));
    return -1;
  }
  return pid;
}

std::string signal_name(int sig) {
  const char* name = ::sigabbrev_np(sig);
  return name != nullptr ? fmt::format("SIG{}", name) : fmt::format("signal {}", sig);
}

// Anything but the console: an earlier attempt's outputs.
bool holds_outputs(const fs::path& dir) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.path().filename() != kSweepConsoleFile) return true;
  }
  return false;
}

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

}  // namespace

fs::path this_executable() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw InputError(fmt::format("cannot find the kairos program: {}", ec.message()));
  return exe;
}

void announce(const SweepPlan& plan, const std::string& line, std::FILE* stream) {
  std::fprintf(stream, "%s\n", line.c_str());
  std::fflush(stream);
  LogFile log;
  if (log.open(plan.directory / kSweepLogFile)) log.line(line);
}

SweepTally run_sweep(const SweepPlan& plan, SweepWork& work, const SweepRunnerOptions& options) {
  SweepTally tally;
  std::vector<Child> running;
  bool exhausted = false;
  bool stopping = false;
  bool start_failed = false;
  const std::size_t workers = static_cast<std::size_t>(std::max(1, options.workers));
  LogFile log;
  log.open(plan.directory / kSweepLogFile);
  auto say = [&](const std::string& line) {
    fmt::print("{}{}\n", options.label, line);
    std::fflush(stdout);
    log.line(options.label + line);
  };
  const auto began = Clock::now();
  auto last_status = began;
  double finished_seconds = 0.0;  // wall time of the runs that ended in this invocation
  std::size_t ended = 0;
  // Runs finished, failed, skipped, running and waiting, the time so far and the ETA: the mean
  // wall time of the runs ended so far for each run left, shared among the workers.
  auto print_status = [&] {
    const std::optional<std::size_t> waiting = work.waiting();
    std::string eta = "ETA unknown (no run ended yet)";
    if (ended > 0 && waiting) {
      // A running run has the mean less its time so far left (at least nothing), a waiting
      // one the mean.
      const double mean = finished_seconds / static_cast<double>(ended);
      double left = mean * static_cast<double>(*waiting);
      for (const Child& c : running) left += std::max(0.0, mean - seconds_since(c.start));
      eta = "ETA " + format_duration(left / static_cast<double>(workers));
    } else if (!waiting) {
      eta = "ETA: see rank 0's share of the runs";
    }
    say(
        fmt::format("status: {} finished, {} failed, {} skipped as done, {} running{}; {} so "
                    "far, {}",
                    tally.finished, tally.failed, tally.skipped, running.size(),
                    waiting ? fmt::format(", {} waiting", *waiting) : std::string(),
                    format_duration(seconds_since(began)), eta));
  };

  auto start = [&](std::size_t index) {
    const SweepPoint& point = plan.points[index];
    const fs::path dir = plan.run_directory(point);
    const SweepRunRecord record = read_sweep_run(dir);
    if (record.state == SweepRunState::kFinished) {
      ++tally.skipped;
      return;
    }
    std::error_code ec;
    fs::create_directories(dir, ec);
    std::vector<std::string> args = plan.run_arguments(point);
    // Only a stopped run goes on from its restart file: a failed one wrote its restart file
    // when it failed (at its end, a whole production would be added), and runs again.
    const bool resume = record.has_restart && record.state == SweepRunState::kStopped;
    if (resume) {
      args.push_back("--restart");
      args.push_back((dir / kRestartFileName).string());
    } else if (holds_outputs(dir)) {
      args.push_back("--overwrite");  // a failed or killed attempt's outputs
    }
    std::string error;
    const pid_t pid = spawn_run(options.executable, args, dir / kSweepConsoleFile, error);
    if (pid < 0) {
      // No process (fork refused, the console not writable): no more are started this
      // invocation; the others end, and the same command takes the rest up later.
      ++tally.not_started;
      start_failed = true;
      work.stop();
      say(fmt::format("{}: could not be started: {}; no further runs are started", point.name,
                      error));
      return;
    }
    running.push_back({pid, index, Clock::now(), false});
    say(fmt::format("{}: {}", point.name, resume ? "continued from its restart.gsd" : "started"));
  };

  auto finish = [&](const Child& child, int status) {
    finished_seconds += seconds_since(child.start);
    ++ended;
    const SweepPoint& point = plan.points[child.index];
    const fs::path dir = plan.run_directory(point);
    const fs::path console = dir / kSweepConsoleFile;
    const std::string wall = format_duration(seconds_since(child.start));
    if (WIFSIGNALED(status) && !child.signalled) {
      append_line(console, fmt::format("kairos sweep: error: the run was killed by {}",
                                       signal_name(WTERMSIG(status))));
    }
    const SweepRunRecord record = read_sweep_run(dir);
    switch (record.state) {
      case SweepRunState::kFinished:
        ++tally.finished;
        say(fmt::format("{}: finished ({}) after {}", point.name,
                        record.summary.value("stop_reason", std::string()), wall));
        break;
      case SweepRunState::kFailed:
        ++tally.failed;
        say(fmt::format("{}: failed after {}: {} (see {})", point.name, wall, record.error,
                        console.string()));
        break;
      default:
        // Stopped: by the sweep, by the wall-time limit (status 0), or by a signal someone
        // sent the run itself (it wrote its outputs and exits with 128 + the signal).
        const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        if (child.signalled || code == 0 || code == 128 + SIGINT || code == 128 + SIGTERM) {
          ++tally.stopped;
          say(fmt::format("{}: stopped after {} ({}); the same sweep command continues it",
                          point.name, wall,
                          record.summary.is_object()
                              ? record.summary.value("stop_reason", std::string("interrupted"))
                              : std::string("before its set-up ended")));
        } else {
          ++tally.failed;
          const std::string why = WIFEXITED(status)
                                      ? fmt::format("exit status {}", WEXITSTATUS(status))
                                      : fmt::format("killed by {}", signal_name(WTERMSIG(status)));
          append_line(console, fmt::format("kairos sweep: error: the run ended with {}", why));
          say(fmt::format("{}: failed after {}: {} (see {})", point.name, wall, why,
                          console.string()));
        }
    }
  };

  for (;;) {
    if (!stopping && stop_requested()) {
      stopping = true;
      tally.interrupted = true;
      work.stop();
      for (Child& c : running) {
        ::kill(c.pid, SIGTERM);
        c.signalled = true;
      }
    }
    while (!stopping && !start_failed && !exhausted && running.size() < workers) {
      const std::optional<std::size_t> index = work.next();
      if (!index) {
        exhausted = true;
      } else {
        start(*index);
      }
    }
    // Our own children only: a host process (Python) may have children of its own.
    for (std::size_t c = 0; c < running.size();) {
      int status = 0;
      if (::waitpid(running[c].pid, &status, WNOHANG) != running[c].pid) {
        ++c;
        continue;
      }
      const Child child = running[c];
      running.erase(running.begin() + static_cast<std::ptrdiff_t>(c));
      finish(child, status);
    }
    if (running.empty() && (exhausted || stopping || start_failed) && !work.serving()) break;
    if (options.status_seconds > 0.0 && !running.empty() &&
        seconds_since(last_status) >= options.status_seconds) {
      print_status();
      last_status = Clock::now();
    }
    work.serve();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return tally;
}

LocalSweepOutcome run_local_sweep(const SweepPlan& plan, const SweepRunnerOptions& options) {
  make_sweep_directory(plan);
  const SweepDirectoryLock lock(plan.directory);
  claim_sweep_directory(plan);
  announce(plan, fmt::format("kairos sweep: {} runs in {}/, {} at a time", plan.points.size(),
                             plan.directory.string(), options.workers));
  LocalSweepWork work(plan.points.size());
  LocalSweepOutcome outcome;
  outcome.tally = run_sweep(plan, work, options);
  outcome.states = write_sweep_results(plan.directory, plan.axes, plan.points);
  return outcome;
}

}  // namespace kairos

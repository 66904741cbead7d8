// The progress of a long set-up step (random insertion, compression, a table build) for whoever
// shows it: the step reports as it goes, the run driver listens while it sets a run up (run.log's
// "setup:" lines, docs/outputs.md#runlog). Like the stop flag, it crosses the layers without
// being passed down every call: a step deep in init/ needs no parameter for it. The listener is
// per thread (four kairos.run threads of the Python module each report to their own run).
#pragma once

#include <functional>
#include <string>

namespace kairos {

// `step`: what is being done, the same text for the whole step ("random insertion of 500000
// particles"); `detail`: how far it is ("120000 placed").
using SetupListener = std::function<void(const std::string& step, const std::string& detail)>;

// While alive, report_setup_progress() calls `listener` on this thread (nested scopes restore
// the enclosing one).
class ScopedSetupListener {
 public:
  explicit ScopedSetupListener(SetupListener listener);
  ~ScopedSetupListener();
  ScopedSetupListener(const ScopedSetupListener&) = delete;
  ScopedSetupListener& operator=(const ScopedSetupListener&) = delete;

 private:
  SetupListener previous_;
};

// Whether a listener is there (a step may skip formatting its detail otherwise).
bool setup_listened() noexcept;

// Tells the listener, if any. Meant for loops that call it every thousand iterations or so: the
// listener decides how often to show it.
void report_setup_progress(const std::string& step, const std::string& detail);

}  // namespace kairos

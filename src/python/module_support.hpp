// What the Python module's files share (kairos_module.cpp, runner_bindings.cpp): arguments read
// from Python objects with errors naming the argument, Ctrl-C during a long call.
#pragma once

#include <pybind11/pybind11.h>

#include <fmt/format.h>
#include <signal.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/stop_flag.hpp"

namespace py = pybind11;
namespace fs = std::filesystem;

namespace kairos {

// Ctrl-C in Python: a long advance (run without the GIL) takes it back every 16 384 events to
// let Python see pending signals.
inline bool python_keeps_going() {
  py::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  return true;
}

inline std::string type_name(const py::handle& object) {
  return py::str(py::type::handle_of(object).attr("__name__")).cast<std::string>();
}

// `set`: None, one "key=value" override, or a sequence (list, tuple) of them. Anything else is a
// TypeError naming what was given (pybind11's own cast error would name C++ types).
inline std::vector<std::string> overrides_from(const py::object& set) {
  if (set.is_none()) return {};
  if (py::isinstance<py::str>(set)) return {set.cast<std::string>()};
  const bool sequence = py::isinstance<py::sequence>(set) && !py::isinstance<py::bytes>(set);
  if (!sequence) {
    throw py::type_error(fmt::format(
        "set must be a 'key=value' string or a list of them (e.g. set=[\"run.time=10\"]), not {}",
        type_name(set)));
  }
  std::vector<std::string> overrides;
  const auto items = set.cast<py::sequence>();
  for (std::size_t i = 0; i < items.size(); ++i) {
    const py::object item = items[i];
    if (!py::isinstance<py::str>(item)) {
      throw py::type_error(
          fmt::format("set[{}] must be a 'key=value' string, not {}", i, type_name(item)));
    }
    overrides.push_back(item.cast<std::string>());
  }
  return overrides;
}

// An optional path argument (`output`, `restart`): None, a str or an os.PathLike; anything else
// is a TypeError naming the argument.
inline std::optional<fs::path> path_from(const py::object& value, const char* name) {
  if (value.is_none()) return std::nullopt;
  if (!py::isinstance<py::str>(value) && !py::hasattr(value, "__fspath__")) {
    throw py::type_error(fmt::format("{} must be a path (str or os.PathLike) or None, not {}", name,
                                     type_name(value)));
  }
  return fs::path(py::module_::import("os").attr("fspath")(value).cast<std::string>());
}

// A number (int, float or a NumPy scalar; not bool).
inline double number_from(const py::object& value, const std::string& name) {
  const bool number = !py::isinstance<py::bool_>(value) && !py::isinstance<py::str>(value) &&
                      (py::hasattr(value, "__float__") || py::hasattr(value, "__index__"));
  if (!number) {
    throw py::type_error(fmt::format("{} must be a number, not {}", name, type_name(value)));
  }
  return py::float_(value).cast<double>();
}

// SIGINT during kairos.run: the run stops cleanly after the current event (request_stop(), as
// in the CLI) and writes every output; Python's handler is back afterwards. During the setup of
// kairos.run or kairos.Simulation (a table build) it unwinds with Interrupted, which the module
// turns into KeyboardInterrupt. For the runners (kairos.sweep, kairos.replica_exchange),
// `second_kills`: a second SIGINT before the first is answered kills the process at once, as in
// the CLI (docs/guarantees.md), the way out of a stop that may not come (a sweep's run that
// does not end, a long round; a sweep's runs get SIGTERM when it dies). A single run stops
// within an event and its outputs' writing, so there a second Ctrl-C (Jupyter's interrupt
// pressed twice) does not kill the session.
extern "C" inline void stop_on_sigint(int) {
  request_stop();
}
class SigintStopsRun {
 public:
  explicit SigintStopsRun(bool second_kills = false) {
    clear_stop_request();
    struct sigaction sa {};
    sa.sa_handler = stop_on_sigint;
    sa.sa_flags = second_kills ? SA_RESETHAND : 0;  // the second one: the default action
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &previous_);
  }
  ~SigintStopsRun() {
    sigaction(SIGINT, &previous_, nullptr);
    clear_stop_request();
  }
  SigintStopsRun(const SigintStopsRun&) = delete;
  SigintStopsRun& operator=(const SigintStopsRun&) = delete;

 private:
  struct sigaction previous_ {};
};

// kairos.sweep and kairos.replica_exchange (runner_bindings.cpp).
void bind_runners(py::module_& m);

}  // namespace kairos

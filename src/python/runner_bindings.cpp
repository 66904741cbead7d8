// kairos.sweep and kairos.replica_exchange: the command line's runners of many simulations
// (docs/sweeps.md, docs/replica_exchange.md) as functions of the Python module.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/error.hpp"
#include "python/module_support.hpp"
#include "replica/replica_exchange.hpp"
#include "sweep/sweep_plan.hpp"
#include "sweep/sweep_runner.hpp"

namespace kairos {
namespace {

// The kairos program that runs a sweep's points: `given`, $KAIROS_BINARY, the build tree's
// (python/../kairos), an installation's (P/lib/python3.X/dist-packages/../../../bin/kairos), or
// the first on the PATH.
fs::path sweep_program(const py::object& given) {
  auto runnable = [](const fs::path& p) {
    std::error_code ec;
    return fs::is_regular_file(p, ec) && ::access(p.c_str(), X_OK) == 0;
  };
  if (const auto p = path_from(given, "kairos")) {
    if (!runnable(*p)) throw InputError(fmt::format("kairos: {} is not a program", p->string()));
    return fs::absolute(*p);
  }
  std::vector<fs::path> candidates;
  if (const char* env = std::getenv("KAIROS_BINARY")) candidates.emplace_back(env);
  const fs::path module =
      fs::path(py::module_::import("kairos").attr("__file__").cast<std::string>()).parent_path();
  candidates.push_back(module / ".." / "kairos");
  candidates.push_back(module / ".." / ".." / ".." / "bin" / "kairos");
  if (const char* path = std::getenv("PATH")) {
    std::string dirs = path;
    for (std::size_t start = 0; start <= dirs.size();) {
      const std::size_t end = std::min(dirs.find(':', start), dirs.size());
      if (end > start) candidates.push_back(fs::path(dirs.substr(start, end - start)) / "kairos");
      start = end + 1;
    }
  }
  for (const fs::path& c : candidates) {
    if (runnable(c)) return fs::absolute(c).lexically_normal();
  }
  throw InputError(
      "kairos.sweep: cannot find the kairos program (beside the module, in an installation's "
      "bin, or on the PATH); pass kairos=PATH or set KAIROS_BINARY");
}

// One value of a `vary` list as --set takes it: numbers and booleans as TOML literals, strings
// as they are, or quoted when a comma, quote or bracket would end or change the value.
std::string sweep_value_text(const py::handle& item, const std::string& where) {
  const py::object value = py::reinterpret_borrow<py::object>(item);
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::str>(value)) {
    const std::string text = value.cast<std::string>();
    // Quoted too when it could be read as A:B:N or I..J (a one-value list is one string).
    const bool plain = !text.empty() && text.find_first_of(",\"'[]{}:") == std::string::npos &&
                       text.find("..") == std::string::npos && text.front() != ' ' &&
                       text.back() != ' ';
    if (plain) return text;  // --set takes a bare word as a string
    std::string quoted = "\"";
    for (const char c : text) {
      if (c == '"' || c == '\\') quoted += '\\';
      quoted += c;
    }
    return quoted + "\"";
  }
  if (py::hasattr(value, "__index__")) return py::str(py::int_(value)).cast<std::string>();
  if (py::hasattr(value, "__float__")) {
    return py::repr(py::float_(value)).cast<std::string>();  // shortest round-trip
  }
  throw py::type_error(
      fmt::format("{} must be a number, a bool or a string, not {}", where, type_name(value)));
}

// `vary`: {key: "A:B:N" | "I..J" | "V1,V2" | [values...]} as --vary arguments, in order.
std::vector<std::string> sweep_axes_from(const py::object& vary) {
  if (!py::isinstance<py::dict>(vary) || py::len(vary) == 0) {
    throw py::type_error(
        fmt::format("vary must be a non-empty dict {{key: values}} (e.g. {{\"system.seed\": "
                    "\"1..4\"}}), not {}",
                    type_name(vary)));
  }
  std::vector<std::string> axes;
  for (const auto& [key, values] : vary.cast<py::dict>()) {
    if (!py::isinstance<py::str>(key)) {
      throw py::type_error(fmt::format("vary: keys must be strings, not {}",
                                       type_name(py::reinterpret_borrow<py::object>(key))));
    }
    const std::string name = key.cast<std::string>();
    if (py::isinstance<py::str>(values)) {
      axes.push_back(name + "=" + values.cast<std::string>());
      continue;
    }
    if (!py::isinstance<py::sequence>(values) || py::len(values) == 0) {
      throw py::type_error(fmt::format(
          "vary[\"{}\"] must be a string (\"A:B:N\", \"I..J\", \"V1,V2\") or a non-empty list",
          name));
    }
    std::string list;
    for (const auto& v : values.cast<py::sequence>()) {
      if (!list.empty()) list += ',';
      list += sweep_value_text(v, fmt::format("vary[\"{}\"]", name));
    }
    axes.push_back(name + "=" + list);
  }
  return axes;
}

}  // namespace

void bind_runners(py::module_& m) {
  m.def(
      "sweep",
      [](const py::object& config, const py::object& output_arg, const py::object& vary,
         const py::object& set, const py::object& workers_arg, const py::object& program) {
        const auto config_path = path_from(config, "config");
        if (!config_path) throw py::type_error("config must be a TOML file's path");
        const std::optional<fs::path> output = path_from(output_arg, "output");
        int workers = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
        if (!workers_arg.is_none()) {
          workers = static_cast<int>(number_from(workers_arg, "workers"));
          if (workers < 1 || workers > 4096 ||
              static_cast<double>(workers) != number_from(workers_arg, "workers")) {
            throw InputError("workers: must be an integer in [1, 4096]");
          }
        }
        const SweepPlan plan = plan_sweep(*config_path, overrides_from(set), sweep_axes_from(vary),
                                          output.value_or("kairos-sweep"));
        const fs::path executable = sweep_program(program);
        const LocalSweepOutcome outcome = [&] {
          SigintStopsRun sigint(/*second_kills=*/true);
          py::gil_scoped_release release;
          return run_local_sweep(plan, {executable, workers, ""});
        }();
        if (outcome.tally.interrupted) {
          PyErr_SetNone(PyExc_KeyboardInterrupt);
          throw py::error_already_set();
        }
        const py::object json = py::module_::import("json");
        const py::object runs =
            json.attr("loads")(py::module_::import("pathlib")
                                   .attr("Path")((plan.directory / "results.json").string())
                                   .attr("read_text")())["runs"];
        std::string failed;
        for (const auto& run : runs) {
          if (run["state"].cast<std::string>() == "failed") {
            failed += fmt::format("\n  {}: {}", run["directory"].cast<std::string>(),
                                  run["error"].cast<std::string>());
          }
        }
        if (!failed.empty()) {
          const std::string message =
              fmt::format("kairos.sweep: runs failed (state 'failed' in the result):{}", failed);
          if (PyErr_WarnEx(PyExc_RuntimeWarning, message.c_str(), 1) != 0) {
            throw py::error_already_set();
          }
        }
        return runs;
      },
      py::arg("config"), py::arg("output") = py::none(), py::arg("vary") = py::none(),
      py::arg("set") = py::none(), py::arg("workers") = py::none(), py::arg("kairos") = py::none(),
      "Runs a grid of simulations as `kairos sweep` does on this machine (docs/sweeps.md). "
      "config: a TOML file's path; output: the sweep directory (default kairos-sweep); vary: "
      "{key: values}, values a string as --vary takes it (\"0.1:0.5:9\", \"1..10\", "
      "\"fcc,sc\") or a list of numbers, bools or strings; set: 'key=value' overrides for every "
      "run; workers: runs at a time (default: the cores); kairos: the kairos program that runs "
      "each point (default: found beside the module, in the installation or on the PATH). "
      "Calling it again continues the sweep. Returns results.json's runs (each: run, directory, "
      "state, error, values, summary); failed runs raise a RuntimeWarning. Ctrl-C stops the "
      "running points cleanly and raises KeyboardInterrupt.");

  m.def(
      "replica_exchange",
      [](const py::object& config, const py::object& output_arg, const py::object& temperatures,
         double interval, std::uint64_t exchanges, std::uint64_t equilibration,
         const py::object& set, const py::object& workers_arg) {
        const auto config_path = path_from(config, "config");
        if (!config_path) throw py::type_error("config must be a TOML file's path");
        ReplicaExchangeSettings settings;
        settings.config = *config_path;
        settings.directory = path_from(output_arg, "output").value_or("kairos-replicas");
        settings.overrides = overrides_from(set);
        if (py::isinstance<py::str>(temperatures)) {
          settings.temperatures = temperatures.cast<std::string>();
        } else {
          for (const auto& t : temperatures) {
            if (!settings.temperatures.empty()) settings.temperatures += ',';
            settings.temperatures += fmt::format(
                "{}", number_from(py::reinterpret_borrow<py::object>(t), "temperatures"));
          }
        }
        settings.interval = interval;
        settings.exchanges = exchanges;
        settings.equilibration = equilibration;
        settings.workers = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
        if (!workers_arg.is_none()) {
          const double w = number_from(workers_arg, "workers");
          if (!(w >= 1 && w <= 4096) || w != std::floor(w))
            throw InputError("workers: must be an integer in [1, 4096]");
          settings.workers = static_cast<int>(w);
        }
        settings.command_line = "kairos.replica_exchange(...)";
        const ReplicaExchangePlan plan = plan_replica_exchange(settings);
        fs::create_directories(plan.settings.directory);
        const SweepDirectoryLock lock(plan.settings.directory);
        claim_replica_directory(plan);
        const ReplicaExchangeOutcome outcome = [&] {
          SigintStopsRun sigint(/*second_kills=*/true);
          py::gil_scoped_release release;
          return run_replica_exchange(plan, ReplicaComm{});
        }();
        if (outcome.stopped) {
          PyErr_SetNone(PyExc_KeyboardInterrupt);
          throw py::error_already_set();
        }
        if (outcome.summary.empty()) return py::object(py::none());
        return py::module_::import("json").attr("loads")(py::module_::import("pathlib")
                                                             .attr("Path")(outcome.summary.string())
                                                             .attr("read_text")());
      },
      py::arg("config"), py::arg("output") = py::none(), py::arg("temperatures"),
      py::arg("interval"), py::arg("exchanges"), py::arg("equilibration") = 0,
      py::arg("set") = py::none(), py::arg("workers") = py::none(),
      "Parallel tempering as `kairos replica-exchange` does on this machine "
      "(docs/replica_exchange.md). config: a TOML file's path with [driving] kind = "
      "\"andersen\"; output: the directory (default kairos-replicas); temperatures: the ladder, "
      "a list of numbers or a string as --temperatures takes it (\"0.5:2:8:log\"); interval: "
      "simulated time between exchange rounds; exchanges: rounds in all; equilibration: first "
      "rounds left out of the statistics; set: 'key=value' overrides; workers: replicas at a "
      "time (default: the cores). Calling it again continues the ensemble from its checkpoint. "
      "Returns summary.json as a dict (None if run.max_wall_seconds stopped it first). Ctrl-C "
      "stops after the current round, with a checkpoint, and raises KeyboardInterrupt.");
}

}  // namespace kairos

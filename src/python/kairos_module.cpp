// The Python module `kairos` (pybind11): kairos.run, the CLI's `kairos run` as a function, and
// kairos.Simulation, an event-driven simulation held in memory (run/simulation.hpp) whose state
// comes back as NumPy arrays. docs/python.md is its user guide.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <fmt/format.h>
#include <signal.h>

#include <atomic>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "core/error.hpp"
#include "core/stop_flag.hpp"
#include "io/config.hpp"
#include "run/run.hpp"
#include "run/simulation.hpp"

namespace py = pybind11;
namespace fs = std::filesystem;

namespace kairos {
namespace {

// Ctrl-C in Python: a long advance (run without the GIL) takes it back every 16 384 events to
// let Python see pending signals.
bool python_keeps_going() {
  py::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  return true;
}

std::string type_name(const py::handle& object) {
  return py::str(py::type::handle_of(object).attr("__name__")).cast<std::string>();
}

// `set`: None, one "key=value" override, or a sequence (list, tuple) of them. Anything else is a
// TypeError naming what was given (pybind11's own cast error would name C++ types).
std::vector<std::string> overrides_from(const py::object& set) {
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
std::optional<fs::path> path_from(const py::object& value, const char* name) {
  if (value.is_none()) return std::nullopt;
  if (!py::isinstance<py::str>(value) && !py::hasattr(value, "__fspath__")) {
    throw py::type_error(fmt::format("{} must be a path (str or os.PathLike) or None, not {}", name,
                                     type_name(value)));
  }
  return fs::path(py::module_::import("os").attr("fspath")(value).cast<std::string>());
}

bool flag_from(const py::object& value, const char* name) {
  if (!py::isinstance<py::bool_>(value))
    throw py::type_error(fmt::format("{} must be True or False, not {}", name, type_name(value)));
  return value.cast<bool>();
}

// A config file (str or path-like), or TOML text when the string holds a newline (a path here
// never does); `set`: one "key=value" override or a sequence of them.
Config config_from(const py::object& config, const py::object& set) {
  const std::vector<std::string> overrides = overrides_from(set);
  if (!py::isinstance<py::str>(config) && !py::hasattr(config, "__fspath__")) {
    throw py::type_error(
        fmt::format("config must be a TOML file's path (str or os.PathLike) or TOML text, not {}",
                    type_name(config)));
  }
  if (py::isinstance<py::str>(config)) {
    const auto text = config.cast<std::string>();
    if (text.find('\n') != std::string::npos) return parse_config(text, "<text>", overrides);
    return load_config(text, overrides);
  }
  const auto path = py::module_::import("os").attr("fspath")(config).cast<std::string>();
  return load_config(path, overrides);
}

// SIGINT during kairos.run: the run stops cleanly after the current event (request_stop(), as
// in the CLI) and writes every output; Python's handler is back afterwards. During the setup of
// kairos.run or kairos.Simulation (a table build) it unwinds with Interrupted, which the module
// turns into KeyboardInterrupt.
extern "C" void stop_on_sigint(int) {
  request_stop();
}
class SigintStopsRun {
 public:
  SigintStopsRun() {
    clear_stop_request();
    struct sigaction sa {};
    sa.sa_handler = stop_on_sigint;
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

py::array_t<double> as_array(const auto& rows, int dimension) {
  py::array_t<double> out({static_cast<py::ssize_t>(rows.size()), py::ssize_t{dimension}});
  auto view = out.template mutable_unchecked<2>();
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (int a = 0; a < dimension; ++a) view(static_cast<py::ssize_t>(i), a) = rows[i][a];
  return out;
}

// kairos.Simulation: one of the two dimensions behind one Python class.
class PySimulation {
 public:
  PySimulation(const py::object& config, const py::object& set, const py::object& restart_arg) {
    const std::optional<fs::path> restart = path_from(restart_arg, "restart");
    const Config c = config_from(config, set);
    // The start may build soft-sphere tables (seconds): without the GIL, and Ctrl-C ends it.
    SigintStopsRun sigint;
    py::gil_scoped_release release;
    if (c.system.dimension == 2) {
      sim_ = std::make_unique<Simulation<2>>(c, restart);
    } else {
      sim_ = std::make_unique<Simulation<3>>(c, restart);
    }
  }

  // Every access goes through visit(): refused while another thread advances this simulation
  // (advance() runs without the GIL).
  template <class F>
  auto visit(F&& f) const {
    if (busy_) throw InputError("this Simulation is advancing in another thread");
    return std::visit([&](const auto& s) { return f(std::as_const(*s)); }, sim_);
  }
  template <class F>
  auto visit(F&& f) {
    if (busy_) throw InputError("this Simulation is advancing in another thread");
    return std::visit([&](auto& s) { return f(*s); }, sim_);
  }

  int dimension() const {
    return visit([](const auto& s) { return dimension_of(s); });
  }
  bool advance(std::optional<double> time, std::optional<std::uint64_t> events,
               std::optional<std::uint64_t> collisions) {
    const int given = (time ? 1 : 0) + (events ? 1 : 0) + (collisions ? 1 : 0);
    if (given != 1) throw InputError("advance: give exactly one of time=, events= or collisions=");
    return visit([&](auto& s) {
      busy_ = true;
      struct Idle {
        std::atomic<bool>& busy;
        ~Idle() { busy = false; }
      } idle{busy_};
      py::gil_scoped_release release;
      if (time) return s.advance_to_time(*time, python_keeps_going);
      if (events) return s.advance_events(*events, python_keeps_going);
      return s.advance_collisions(*collisions, python_keeps_going);
    });
  }
  py::array_t<double> positions() const {
    return visit([](const auto& s) { return as_array(s.positions(), dimension_of(s)); });
  }
  py::array_t<double> velocities() const {
    return visit([](const auto& s) { return as_array(s.velocities(), dimension_of(s)); });
  }
  py::array_t<double> box() const {
    return visit([](const auto& s) {
      const auto& b = s.box();
      return py::array_t<double>(static_cast<py::ssize_t>(b.size()), b.data());
    });
  }
  py::array_t<double> masses() const {
    return visit([](const auto& s) { return py::array_t<double>(py::cast(s.masses())); });
  }
  py::array_t<double> radii() const {
    return visit([](const auto& s) { return py::array_t<double>(py::cast(s.radii())); });
  }
  py::array_t<std::uint32_t> species() const {
    return visit([](const auto& s) { return py::array_t<std::uint32_t>(py::cast(s.species())); });
  }
  std::vector<std::string> species_names() const {
    return visit([](const auto& s) { return s.species_names(); });
  }
  double time() const {
    return visit([](const auto& s) { return s.time(); });
  }
  std::uint64_t events() const {
    return visit([](const auto& s) { return s.events(); });
  }
  std::uint64_t collisions() const {
    return visit([](const auto& s) { return s.collisions(); });
  }
  std::size_t size() const {
    return visit([](const auto& s) { return s.size(); });
  }
  double kinetic_energy() const {
    return visit([](const auto& s) { return s.kinetic_energy(); });
  }
  double temperature() const {
    return visit([](const auto& s) { return s.temperature(); });
  }
  double potential_energy() const {
    return visit([](const auto& s) { return s.potential_energy(); });
  }
  std::string repr() const {
    return visit([](const auto& s) {
      return fmt::format("<kairos.Simulation: {} particles in {}D, t = {:.6g}, {} collisions>",
                         s.size(), dimension_of(s), s.time(), s.collisions());
    });
  }
  void save(const fs::path& path) const {
    visit([&](const auto& s) { s.save(path); });
  }

 private:
  template <int D>
  static int dimension_of(const Simulation<D>&) {
    return D;
  }
  std::variant<std::unique_ptr<Simulation<2>>, std::unique_ptr<Simulation<3>>> sim_;
  std::atomic<bool> busy_{false};
};

}  // namespace
}  // namespace kairos

PYBIND11_MODULE(kairos, m) {
  using kairos::PySimulation;
  m.doc() =
      "Kairos, event-driven particle dynamics: kairos.run (the `kairos run` command) and "
      "kairos.Simulation (a simulation in memory, its state as NumPy arrays). docs/python.md.";
  m.attr("__version__") = KAIROS_VERSION;
  // A configuration or state the user must fix; Python's ValueError family.
  py::register_exception<kairos::InputError>(m, "InputError", PyExc_ValueError);
  // A setup stopped by Ctrl-C is Python's KeyboardInterrupt; one stopped by run.max_wall_seconds
  // a TimeoutError.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const kairos::Interrupted& e) {
      if (e.cause() == kairos::Interrupted::Cause::kWallTime) {
        PyErr_SetString(
            PyExc_TimeoutError,
            fmt::format("run.max_wall_seconds: {} during the setup; nothing was run", e.what())
                .c_str());
      } else {
        PyErr_SetNone(PyExc_KeyboardInterrupt);
      }
    }
  });

  m.def(
      "run",
      [](const py::object& config, const py::object& output_arg, const py::object& set,
         const py::object& restart_arg, const py::object& overwrite_arg) {
        const std::optional<fs::path> output = kairos::path_from(output_arg, "output");
        const std::optional<fs::path> restart = kairos::path_from(restart_arg, "restart");
        const bool overwrite = kairos::flag_from(overwrite_arg, "overwrite");
        kairos::Config c = kairos::config_from(config, set);
        if (output) c.output.directory = output->string();
        const kairos::RunOutcome outcome = [&] {
          kairos::SigintStopsRun sigint;
          const kairos::ScopedStopDeadline setup_limit(c.run.max_wall_seconds);
          py::gil_scoped_release release;  // the run is C++ throughout
          kairos::RunOptions options;
          options.overwrite = overwrite;
          return kairos::run_simulation(c, restart, options);
        }();
        if (outcome.summary.value("stop_reason", "") == "signal") {
          // Ctrl-C: the outputs are written (summary.json says "signal"); Python's way is this.
          PyErr_SetNone(PyExc_KeyboardInterrupt);
          throw py::error_already_set();
        }
        // A run that could not go on (a frozen clock...): outputs written, the reason raised.
        if (!outcome.error.empty()) throw kairos::InputError(outcome.error);
        return py::module_::import("json").attr("loads")(outcome.summary.dump());
      },
      py::arg("config"), py::arg("output") = py::none(), py::arg("set") = py::none(),
      py::arg("restart") = py::none(), py::arg("overwrite") = false,
      "Runs a simulation as `kairos run` does (config: a TOML file's path, or TOML text; set: "
      "'key=value' overrides; output: the output directory; restart: a restart file to "
      "continue; overwrite: replace an earlier run's outputs in the directory). Writes the usual "
      "output files and returns summary.json as a dict. Ctrl-C "
      "stops the run cleanly (every output written) and raises KeyboardInterrupt.");

  py::class_<PySimulation>(m, "Simulation",
                           "An event-driven simulation in memory: the engine of `kairos run` "
                           "started from the same configuration (bit-identical trajectory), "
                           "advanced on request, without output files.")
      .def(py::init<const py::object&, const py::object&, const py::object&>(), py::arg("config"),
           py::arg("set") = py::none(), py::arg("restart") = py::none(),
           "config: a TOML file's path, or TOML text; set: 'key=value' overrides; restart: a "
           "restart file to continue from.")
      .def("advance", &PySimulation::advance, py::arg("time") = py::none(),
           py::arg("events") = py::none(), py::arg("collisions") = py::none(),
           "Advances to simulated time `time` (exactly; no event needs to happen then), or by "
           "`events` events, or by `collisions` collisions (one of the three). Returns False if "
           "no event was left before the target.")
      .def("positions", &PySimulation::positions,
           "Positions at the present time, an (N, D) array, wrapped into the periodic box.")
      .def("velocities", &PySimulation::velocities, "Velocities at the present time, (N, D).")
      .def("masses", &PySimulation::masses)
      .def("radii", &PySimulation::radii)
      .def("species", &PySimulation::species, "Species index of each particle.")
      .def_property_readonly("species_names", &PySimulation::species_names)
      .def_property_readonly("box", &PySimulation::box, "Box edges, (D,).")
      .def_property_readonly("dimension", &PySimulation::dimension)
      .def_property_readonly("time", &PySimulation::time)
      .def_property_readonly("events", &PySimulation::events)
      .def_property_readonly("collisions", &PySimulation::collisions)
      .def("__len__", &PySimulation::size)
      .def("kinetic_energy", &PySimulation::kinetic_energy)
      .def("temperature", &PySimulation::temperature,
           "kT as thermo.tsv gives it: D (N - 1) degrees of freedom; under shear, of the "
           "velocities relative to the flow.")
      .def("potential_energy", &PySimulation::potential_energy,
           "Of the stepped potentials, or the elastic energy of soft contacts in progress.")
      .def("__repr__", &PySimulation::repr)
      .def("save", &PySimulation::save, py::arg("path"),
           "Writes a restart file (atomically) that `kairos run --restart` continues.");
}

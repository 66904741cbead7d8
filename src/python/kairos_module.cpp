// The Python module `kairos` (pybind11): kairos.run, the CLI's `kairos run` as a function,
// kairos.Simulation, a simulation held in memory (run/simulation.hpp: the event engine or the
// DEM) whose state
// and analyses (run/simulation_analyses.hpp) come back as NumPy arrays, and kairos.Correlator,
// the multiple-tau correlator of analysis.msd (analysis/msd.hpp) fed by the user.
// kairos.sweep and kairos.replica_exchange are in runner_bindings.cpp, the helpers both files
// use in module_support.hpp. docs/python.md is its user guide.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <fmt/format.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <variant>
#include <vector>

#include "analysis/msd.hpp"
#include "core/error.hpp"
#include "core/stop_flag.hpp"
#include "io/config.hpp"
#include "python/module_support.hpp"
#include "run/outputs/compression_output.hpp"
#include "run/outputs/transport_output.hpp"
#include "run/run.hpp"
#include "run/simulation.hpp"
#include "run/simulation_analyses.hpp"

namespace py = pybind11;
namespace fs = std::filesystem;

namespace kairos {
namespace {

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

py::array_t<double> as_array(const auto& rows, int dimension) {
  py::array_t<double> out({static_cast<py::ssize_t>(rows.size()), py::ssize_t{dimension}});
  auto view = out.template mutable_unchecked<2>();
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (int a = 0; a < dimension; ++a) view(static_cast<py::ssize_t>(i), a) = rows[i][a];
  return out;
}

// ----- arguments of the analyses: a wrong type is a TypeError, a wrong value an InputError,
// each naming the argument ("msd: interval").

// A positive finite number, or None (0: automatic, as `none_means` says) where one is allowed.
double positive_from(const py::object& value, const std::string& name,
                     const char* none_means = nullptr) {
  if (none_means != nullptr && value.is_none()) return 0.0;
  const double x = number_from(value, name);
  if (!(x > 0.0) || !std::isfinite(x)) {
    throw InputError(fmt::format(
        "{} must be a positive finite number{}, not {}", name,
        none_means != nullptr ? fmt::format(" (or None: {})", none_means) : std::string(), x));
  }
  return x;
}

double non_negative_from(const py::object& value, const std::string& name) {
  const double x = number_from(value, name);
  if (!(x >= 0.0) || !std::isfinite(x))
    throw InputError(fmt::format("{} must be a finite number >= 0, not {}", name, x));
  return x;
}

long long integer_from(const py::object& value, const std::string& name) {
  if (py::isinstance<py::bool_>(value) || !py::hasattr(value, "__index__")) {
    throw py::type_error(fmt::format("{} must be an integer, not {}", name, type_name(value)));
  }
  const py::int_ i(value);
  try {
    return i.cast<long long>();
  } catch (const py::cast_error&) {
    throw InputError(
        fmt::format("{} is out of range: {}", name, py::str(py::handle(i)).cast<std::string>()));
  }
}

// A fit window [from, to] (None: the automatic one, as analysis.msd_fit_from / msd_fit_to).
std::pair<double, double> fit_window_from(const py::object& from_arg, const py::object& to_arg,
                                          const std::string& where) {
  const double from = positive_from(from_arg, where + ": fit_from", "automatic");
  const double to = positive_from(to_arg, where + ": fit_to", "automatic");
  if (from > 0.0 && to > 0.0 && !(to > from)) {
    throw InputError(
        fmt::format("{}: fit_to ({}) must be greater than fit_from ({})", where, to, from));
  }
  return {from, to};
}

// ----- results as NumPy arrays

template <class T>
py::array_t<T> array_of(const std::vector<T>& v) {
  return py::array_t<T>(static_cast<py::ssize_t>(v.size()), v.data());
}

// rows x cols, element (i, j) = at(i, j).
template <class T = double, class F>
py::array_t<T> matrix_of(std::size_t rows, std::size_t cols, F&& at) {
  py::array_t<T> out({static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(cols)});
  auto view = out.template mutable_unchecked<2>();
  for (std::size_t i = 0; i < rows; ++i)
    for (std::size_t j = 0; j < cols; ++j)
      view(static_cast<py::ssize_t>(i), static_cast<py::ssize_t>(j)) = at(i, j);
  return out;
}

// A correlator's fits, one entry per group (NaN, 0 where a group has none).
template <class Fit>
py::dict fits_dict(const std::vector<std::optional<Fit>>& fits) {
  const double nan = std::nan("");
  std::vector<double> coefficient, stderr_, particles, epochs;
  std::vector<std::int64_t> lags, epoch_count;
  for (const auto& f : fits) {
    coefficient.push_back(f ? f->coefficient : nan);
    stderr_.push_back(f ? f->stderr_ : nan);
    particles.push_back(f ? f->particle_stderr : nan);
    epochs.push_back(f ? f->epoch_stderr : nan);
    lags.push_back(f ? f->lags : 0);
    epoch_count.push_back(f ? f->epochs : 0);
  }
  py::dict out;
  out["coefficient"] = array_of(coefficient);
  out["stderr"] = array_of(stderr_);
  out["stderr_particles"] = array_of(particles);
  out["stderr_epochs"] = array_of(epochs);
  out["lags_fitted"] = array_of(lags);
  out["epochs_fitted"] = array_of(epoch_count);
  return out;
}

// A correlator's lags: lag, origins and the mean per group (and for displacements the
// non-Gaussian parameter).
template <int D>
py::dict lags_dict(const MsdCorrelator<D>& c, bool displacement, const char* mean_name) {
  const auto lags = c.lags();
  std::vector<double> lag;
  std::vector<std::uint64_t> origins;
  for (const auto& l : lags) {
    lag.push_back(l.lag);
    origins.push_back(l.origins);
  }
  const std::size_t groups = lags.empty() ? 0 : lags[0].mean.size();
  py::dict out;
  out["lag"] = array_of(lag);
  out["origins"] = array_of(origins);
  out[mean_name] = matrix_of(lags.size(), groups, [&](auto i, auto g) { return lags[i].mean[g]; });
  if (displacement) {
    out["non_gaussian"] =
        matrix_of(lags.size(), groups, [&](auto i, auto g) { return lags[i].non_gaussian[g]; });
  }
  return out;
}

// A mixture's interdiffusion, as summary.json's diffusion.mutual: per moment (a species against
// the other of two, or against the rest) its pair name, mole fraction, coefficient and error
// (the time epochs'), Darken's estimate for two species; the moments' mean squares per lag.
template <int D>
py::dict mutual_dict(const MsdMeasurement<D>& m) {
  const InterdiffusionMoments<D>& moments = *m.interdiffusion;
  const double nan = std::nan("");
  std::vector<std::string> pairs;
  std::vector<double> fraction, coefficient, error, darken;
  const auto name = [&](std::uint32_t s) {
    return s < m.species.size() ? m.species[s] : std::to_string(s);
  };
  for (std::size_t k = 0; k < moments.count(); ++k) {
    const std::uint32_t a = moments.species(k);
    pairs.push_back(name(a) + "-" + (moments.binary() ? name(moments.partner()) : "rest"));
    fraction.push_back(moments.mole_fraction(k));
    const auto& fit = m.mutual_fits[k];
    coefficient.push_back(fit ? fit->coefficient : nan);
    error.push_back(fit ? fit->epoch_stderr : nan);
    double d = nan;
    const std::uint32_t b = moments.partner();
    if (moments.binary() && m.diffusion.size() > std::max(a, b) && m.diffusion[a] &&
        m.diffusion[b]) {
      const double x = moments.mole_fraction(k);
      d = (1.0 - x) * m.diffusion[a]->coefficient + x * m.diffusion[b]->coefficient;
    }
    darken.push_back(d);
  }
  py::dict out = lags_dict(*m.mutual, false, "msd");
  out["pairs"] = pairs;
  out["mole_fraction"] = array_of(fraction);
  out["coefficient"] = array_of(coefficient);
  out["coefficient_stderr"] = array_of(error);
  out["darken"] = array_of(darken);
  return out;
}

// What a measurement in time sampled, into `out`.
void span_into(py::dict& out, const SampledSpan& span, std::uint64_t samples, double first,
               double last) {
  out["interval"] = span.interval;
  out["interval_automatic"] = span.interval_automatic;
  out["samples"] = samples;
  out["sampled_from"] = samples > 0 ? first : std::nan("");
  out["sampled_to"] = samples > 0 ? last : std::nan("");
  out["mean_free_time"] = span.mean_free_time;
  out["fit_from"] = span.fit_from;
  out["fit_to"] = span.fit_to;
}

// kairos.Simulation: one of the two dimensions behind one Python class.
class PySimulation {
 public:
  PySimulation(const py::object& config, const py::object& set, const py::object& restart_arg,
               const py::object& images_arg, const py::object& helfand_arg) {
    const std::optional<fs::path> restart = path_from(restart_arg, "restart");
    EngineTracking tracking;
    tracking.images = flag_from(images_arg, "images");
    tracking.helfand = flag_from(helfand_arg, "helfand");
    const Config c = config_from(config, set);
    // The start may build soft-sphere tables (seconds): without the GIL, and Ctrl-C ends it.
    SigintStopsRun sigint;
    py::gil_scoped_release release;
    if (c.system.dimension == 2) {
      sim_ = std::make_unique<Simulation<2>>(c, restart, tracking);
    } else {
      sim_ = std::make_unique<Simulation<3>>(c, restart, tracking);
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

  // Runs f() without the GIL (the simulation advances: other Python threads go on, and any
  // other use of this Simulation from them is refused until it returns).
  template <class F>
  auto advancing(F&& f) {
    if (in_callback_) throw InputError("not from inside an advance's callback");
    busy_ = true;
    struct Idle {
      std::atomic<bool>& busy;
      ~Idle() { busy = false; }
    } idle{busy_};
    py::gil_scoped_release release;
    return f();
  }

  // callback(self) at each multiple of `every` (in the target's unit: time after the present,
  // or events / collisions counted from now) up to the target, with the GIL and the object free
  // (it may read or change the state, e.g. set_velocities); False from it stops the advance.
  struct CallbackStop {};
  bool advance_with_callback(std::optional<double> time, std::optional<std::uint64_t> events,
                             std::optional<std::uint64_t> collisions, const py::object& every,
                             const py::object& callback) {
    if (!PyCallable_Check(callback.ptr()))
      throw py::type_error("advance: callback must be callable, not " + type_name(callback));
    const double step = number_from(every, "every");
    if (!time && (!(step >= 1.0) || step != std::floor(step) || step > 0x1p62)) {
      throw InputError(
          fmt::format("advance: every = {} must be a whole number >= 1 of {} for an advance by {}",
                      step, events ? "events" : "collisions", events ? "events" : "collisions"));
    }
    const py::object self = py::cast(this, py::return_value_policy::reference);
    const auto call = [&] {
      // The flags change only while this thread holds the GIL: no other Python thread can
      // find the object free while the advance goes on.
      py::gil_scoped_acquire gil;
      struct Back {
        PySimulation& sim;
        ~Back() {
          sim.busy_ = true;
          sim.in_callback_ = false;
        }
      };
      in_callback_ = true;
      busy_ = false;
      const Back back{*this};
      const py::object answer = callback(self);
      if (answer.is_none()) return;
      const int truth = PyObject_IsTrue(answer.ptr());
      if (truth < 0) throw py::error_already_set();
      if (truth == 0) throw CallbackStop{};
    };
    return visit([&](auto& s) {
      try {
        return advancing([&] {
          if (time) {
            if (!(*time >= s.time()) || !std::isfinite(*time))
              return s.advance_to_time(*time, python_keeps_going);  // its error
            return s.sample_every(step, *time - s.time(), call, python_keeps_going);
          }
          const auto n = static_cast<std::uint64_t>(step);
          if (events) return s.sample_every_events(n, *events, call, python_keeps_going);
          return s.sample_every_collisions(n, *collisions, call, python_keeps_going);
        });
      } catch (const CallbackStop&) {
        return false;
      }
    });
  }

  int dimension() const {
    return visit([](const auto& s) { return dimension_of(s); });
  }
  bool advance(std::optional<double> time, std::optional<std::uint64_t> events,
               std::optional<std::uint64_t> collisions, const py::object& every,
               const py::object& callback) {
    const int given = (time ? 1 : 0) + (events ? 1 : 0) + (collisions ? 1 : 0);
    if (given != 1) throw InputError("advance: give exactly one of time=, events= or collisions=");
    if (every.is_none() != callback.is_none())
      throw InputError("advance: give every= and callback= together");
    if (!callback.is_none())
      return advance_with_callback(time, events, collisions, every, callback);
    return visit([&](auto& s) {
      return advancing([&] {
        if (time) return s.advance_to_time(*time, python_keeps_going);
        if (events) return s.advance_events(*events, python_keeps_going);
        return s.advance_collisions(*collisions, python_keeps_going);
      });
    });
  }
  py::array_t<double> positions() const {
    return visit([](const auto& s) { return as_array(s.positions(), dimension_of(s)); });
  }
  py::array_t<double> velocities() const {
    return visit([](const auto& s) { return as_array(s.velocities(), dimension_of(s)); });
  }
  void set_velocities(const py::object& values) {
    visit([&]<int D>(Simulation<D>& s) {
      s.set_velocities(vectors_from<D>(values, "set_velocities", "velocities"));
    });
  }
  void set_positions(const py::object& values) {
    visit([&]<int D>(Simulation<D>& s) {
      s.set_positions(vectors_from<D>(values, "set_positions", "positions"));
    });
  }
  // An (N, D) array of numbers; TypeError naming the call and what was given otherwise.
  template <int D>
  static std::vector<Vec<D>> vectors_from(const py::object& values, const char* call,
                                          const char* what) {
    const auto array =
        py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(values);
    if (!array || array.ndim() != 2 || array.shape(1) != D) {
      throw py::type_error(fmt::format("{}: {} must be an (N, {}) array of numbers, not {}", call,
                                       what, D, type_name(values)));
    }
    const auto view = array.template unchecked<2>();
    std::vector<Vec<D>> out(static_cast<std::size_t>(array.shape(0)));
    for (std::size_t i = 0; i < out.size(); ++i)
      for (int a = 0; a < D; ++a) out[i][a] = view(static_cast<py::ssize_t>(i), a);
    return out;
  }
  void set_species(const py::object& values) {
    visit([&](auto& s) {
      const auto array = py::array_t<long long, py::array::c_style>::ensure(values);
      if (!array || array.ndim() != 1 || py::isinstance<py::str>(values)) {
        throw py::type_error("set_species: species must be a 1-d array of integers, not " +
                             type_name(values));
      }
      const auto view = array.template unchecked<1>();
      std::vector<std::uint32_t> k(static_cast<std::size_t>(array.shape(0)));
      for (std::size_t i = 0; i < k.size(); ++i) {
        const long long v = view(static_cast<py::ssize_t>(i));
        if (v < 0 || v > 0xffffffffLL)
          throw InputError(fmt::format("set_species: particle {}: species {} out of range", i, v));
        k[i] = static_cast<std::uint32_t>(v);
      }
      s.set_species(k);
    });
  }
  void set_thermostat_temperature(double temperature) {
    visit([&](auto& s) { s.set_thermostat_temperature(temperature); });
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
  // summary.json's `compression` (and what it leaves undefined) with the history of compress.tsv
  // as NumPy columns; None if the start state was not compressed.
  py::object compression() const {
    return visit([](const auto& s) -> py::object {
      const CompressionReport* report = s.compression();
      if (report == nullptr) return py::none();
      nlohmann::json summary;
      summarize_compression(*report, dimension_of(s), summary);
      py::dict out = py::module_::import("json").attr("loads")(summary["compression"].dump());
      if (summary.contains("undefined")) {
        out["undefined"] = py::module_::import("json").attr("loads")(summary["undefined"].dump());
      }
      const std::vector<CompressionRow>& rows = report->result.rows;
      const auto column = [&](auto field) {
        py::array_t<double> a(static_cast<py::ssize_t>(rows.size()));
        auto v = a.mutable_unchecked<1>();
        for (std::size_t k = 0; k < rows.size(); ++k)
          v(static_cast<py::ssize_t>(k)) = static_cast<double>(field(rows[k]));
        return a;
      };
      py::dict history;
      history["time"] = column([](const CompressionRow& r) { return r.time; });
      history["packing_fraction"] =
          column([](const CompressionRow& r) { return r.packing_fraction; });
      history["reduced_pressure"] = column([](const CompressionRow& r) { return r.pressure; });
      history["kT_before_rescaling"] =
          column([](const CompressionRow& r) { return r.temperature; });
      history["collisions"] = column([](const CompressionRow& r) { return r.collisions; });
      history["collision_rate"] = column([](const CompressionRow& r) { return r.collision_rate; });
      out["history"] = history;
      return out;
    });
  }
  py::list walls_with_mass() const {
    const std::vector<WallReading> walls = visit([](const auto& s) { return s.walls_with_mass(); });
    py::list out;
    for (const WallReading& w : walls) {
      py::dict d;
      d["face"] = w.face;
      d["position"] = w.position;
      d["speed"] = w.speed;
      d["energy"] = w.energy;
      d["mass"] = w.mass;
      d["container"] = w.container;
      if (!w.container) {
        d["force"] = w.force;
        d["pressure"] = w.pressure;
      }
      if (w.sprung) {
        d["drive_work"] = w.drive_work;
        d["dashpot_dissipated"] = w.dashpot;
      }
      out.append(d);
    }
    return out;
  }
  // An outlet's tally since the start of the simulation (None without [boundary.outlet]).
  py::object outlet() const {
    return visit([](const auto& s) -> py::object {
      const auto o = s.integrator().outlet();
      if (!o) return py::none();
      py::dict d;
      d["passes"] = o->passes;
      d["mass"] = o->mass;
      d["energy_taken"] = o->energy;
      d["waiting"] = o->waiting >= 0 ? py::object(py::int_(o->waiting)) : py::object(py::none());
      return d;
    });
  }
  bool tracks_images() const {
    return visit([](const auto& s) { return s.tracks_images(); });
  }
  bool tracks_helfand() const {
    return visit([](const auto& s) { return s.tracks_helfand(); });
  }
  py::array_t<double> unwrapped_positions() const {
    return visit([](const auto& s) { return as_array(s.unwrapped_positions(), dimension_of(s)); });
  }
  py::array_t<std::int32_t> images() const {
    return visit([](const auto& s) {
      const auto images = s.images();
      return matrix_of<std::int32_t>(images.size(), static_cast<std::size_t>(dimension_of(s)),
                                     [&](auto i, auto a) { return images[i][a]; });
    });
  }

  py::dict rdf(const py::object& bins_arg, const py::object& r_max_arg) const {
    const long long bins = integer_from(bins_arg, "rdf: bins");
    if (bins < 1 || bins > 10'000'000)
      throw InputError(fmt::format("rdf: bins must be between 1 and 10^7, not {}", bins));
    const double r_max = positive_from(
        r_max_arg, "rdf: r_max", "5 of the largest diameters, at most half the shortest edge");
    return visit([&](const auto& s) {
      const auto g = rdf_now(s, static_cast<int>(bins), r_max);
      py::dict out, per_pair, contact, sigma;
      out["r"] = array_of(g.r);
      for (std::size_t p = 0; p < g.pairs.size(); ++p) {
        per_pair[py::str(g.pairs[p])] = array_of(g.g[p]);
        contact[py::str(g.pairs[p])] = g.contact[p];
        sigma[py::str(g.pairs[p])] = g.sigma[p];
      }
      out["g"] = per_pair;
      out["g_all"] = array_of(g.g_all);
      out["contact"] = contact;
      out["sigma"] = sigma;
      out["no_contact"] = g.no_contact.empty() ? py::object(py::none()) : py::str(g.no_contact);
      out["r_max"] = g.max_distance;
      out["bin_width"] = g.max_distance / g.bins;
      out["overlapping_pairs"] = g.overlapping;
      out["pairs_at_contact"] = g.at_contact;
      return out;
    });
  }

  py::dict structure_factor(const py::object& k_max_arg) const {
    const double k_max = positive_from(k_max_arg, "structure_factor: k_max", "15 / d");
    return visit([&](const auto& s) {
      double d = 0.0;
      for (const double r : s.radii()) d = std::max(d, 2.0 * r);
      if (k_max > 100.0 / d) {
        throw InputError(fmt::format(
            "structure_factor: k_max must be at most 100 / d = {:.6g} (d = {:.6g}, the largest "
            "diameter; as analysis.sk_max), not {}",
            100.0 / d, d, k_max));
      }
      const StructureFactorNow sk = structure_factor_now(s, k_max);
      py::dict out;
      out["k"] = array_of(sk.k);
      out["S"] = array_of(sk.s);
      out["vectors"] = array_of(sk.vectors);
      out["available"] = array_of(sk.available);
      out["s_zero"] = sk.s_zero;
      out["fit_max"] = sk.fit_max;
      out["fit_shells"] = sk.fit_shells;
      out["k_max"] = sk.k_max;
      return out;
    });
  }

  py::dict bond_order(const py::object& cutoff_arg) const {
    const double cutoff = number_from(cutoff_arg, "bond_order: cutoff");
    if (!(cutoff >= 1.0 && cutoff <= 3.0)) {
      throw InputError(
          fmt::format("bond_order: cutoff must be between 1 and 3 contact distances (as "
                      "analysis.bond_cutoff), not {}",
                      cutoff));
    }
    return visit([&](const auto& s) {
      const auto b = bond_order_now(s, cutoff, "bond_order: cutoff");
      py::dict out;
      for (std::size_t ch = 0; ch < b.names.size(); ++ch) {
        out[py::str(b.names[ch])] = array_of(b.local[ch]);
        out[py::str(b.names[ch] + "_global")] = b.global[ch];
      }
      out["bonds"] = b.bonds;
      out["isolated"] = b.isolated;
      out["cutoff"] = cutoff;
      return out;
    });
  }

  py::dict velocity_distribution() const {
    return visit([&](const auto& s) {
      const auto v = velocity_distribution_now(s);
      using V = std::decay_t<decltype(v)>;
      if (v.samples() == 0) throw InputError("velocity_distribution: the particles are at rest");
      const int dimension = dimension_of(s);
      std::vector<double> w, p, maxwellian;
      for (int k = 0; k < V::kBins; ++k) {
        w.push_back(0.5 * (v.bin_low(k) + v.bin_low(k + 1)));
        p.push_back(v.density(k).mean);
        maxwellian.push_back(v.maxwellian(k));
      }
      py::dict out;
      out["w"] = array_of(w);
      out["p"] = array_of(p);
      out["p_axis"] = matrix_of(
          static_cast<std::size_t>(V::kBins), static_cast<std::size_t>(dimension),
          [&](auto k, auto a) { return v.density(static_cast<int>(k), static_cast<int>(a)).mean; });
      out["maxwellian"] = array_of(maxwellian);
      out["kurtosis"] = v.kurtosis().mean;
      out["sonine_a2"] = v.sonine_a2().mean;
      out["tail_ratio"] = v.tail_ratio().mean;
      out["outside"] = v.outside();
      return out;
    });
  }

  py::dict msd(const py::object& interval_arg, const py::object& duration_arg,
               const py::object& fit_from_arg, const py::object& fit_to_arg,
               const py::object& vacf_arg, const py::object& particles_arg,
               const py::object& clock_arg, const py::object& mutual_arg) {
    CorrelationRequest request =
        correlation_request(interval_arg, duration_arg, fit_from_arg, fit_to_arg, "msd");
    const bool vacf = flag_from(vacf_arg, "msd: vacf");
    const bool mutual = flag_from(mutual_arg, "msd: mutual");
    if (!py::isinstance<py::str>(clock_arg))
      throw py::type_error("msd: clock must be a string: \"auto\", \"time\" or \"collisions\"");
    const std::string clock_name = clock_arg.cast<std::string>();
    const auto clock = msd_time_scales().find(clock_name);
    if (!clock) {
      throw InputError(fmt::format("msd: clock = \"{}\": one of {}", clock_name,
                                   msd_time_scales().names(", ", " or ")));
    }
    std::size_t particles = 0;  // all
    if (!particles_arg.is_none()) {
      const double wanted = number_from(particles_arg, "msd: particles");
      if (!(wanted >= 1.0) || wanted != std::floor(wanted) || wanted > 1e9)
        throw InputError("msd: particles: a whole number >= 1 (or None: every particle)");
      particles = static_cast<std::size_t>(wanted);
    }
    return visit([&](auto& s) {
      const auto m = advancing([&] {
        return measure_msd(s, request, vacf, python_keeps_going, particles, clock->value, mutual);
      });
      py::dict out = lags_dict(*m.msd, true, "msd");
      out["species"] = m.species;
      out["particles_followed"] = m.followed;
      py::dict fits = fits_dict(m.diffusion);
      out["diffusion"] = fits["coefficient"];
      out["diffusion_stderr"] = fits["stderr"];
      out["diffusion_stderr_particles"] = fits["stderr_particles"];
      out["diffusion_stderr_epochs"] = fits["stderr_epochs"];
      out["lags_fitted"] = fits["lags_fitted"];
      out["epochs_fitted"] = fits["epochs_fitted"];
      span_into(out, m.span, m.msd->samples(), m.sampled_from, m.sampled_to);
      out["clock"] = m.in_collisions ? "collisions" : "time";
      if (m.mutual) out["mutual"] = mutual_dict(m);
      out["why"] =
          m.no_coefficient.empty() ? py::object(py::none()) : py::object(py::str(m.no_coefficient));
      if (m.vacf) {
        out["vacf"] = lags_dict(*m.vacf, false, "vacf");
        py::dict gk = fits_dict(m.green_kubo);
        out["green_kubo"] = gk["coefficient"];
        out["green_kubo_stderr"] = gk["stderr"];
      }
      return out;
    });
  }

  py::dict helfand_moments() const {
    return visit([](const auto& s) {
      const int d = dimension_of(s);
      const auto m = s.helfand_moments();
      const std::array<double, 9>& virial = s.virial_tensor();
      const auto dd = static_cast<std::size_t>(d);
      const auto at = [d](const std::array<double, 9>& t) {
        return [&t, d](std::size_t a, std::size_t b) { return t[a * d + b]; };
      };
      py::dict out;
      out["time"] = s.time();
      out["kinetic_stress"] = matrix_of(dd, dd, at(m.kinetic_stress));
      out["virial"] = matrix_of(dd, dd, at(virial));
      out["jump_stress"] = matrix_of(dd, dd, at(m.jump_stress));
      out["frozen_pair_time"] = m.frozen_pair_time;
      out["frozen_kinetic"] = m.frozen_kinetic;
      out["stress"] = matrix_of(dd, dd, [&](std::size_t a, std::size_t b) {
        return m.kinetic_stress[a * dd + b] + virial[a * dd + b] + m.jump_stress[a * dd + b];
      });
      std::vector<double> kinetic, collisional, energy;
      for (int a = 0; a < d; ++a) {
        kinetic.push_back(m.kinetic_energy_flux[a]);
        collisional.push_back(m.collisional_energy_flux[a]);
        energy.push_back(m.kinetic_energy_flux[a] + m.collisional_energy_flux[a]);
      }
      out["energy_kinetic"] = array_of(kinetic);
      out["energy_collisional"] = array_of(collisional);
      out["energy"] = array_of(energy);
      return out;
    });
  }

  py::dict transport(const py::object& interval_arg, const py::object& duration_arg,
                     const py::object& fit_from_arg, const py::object& fit_to_arg) {
    CorrelationRequest request =
        correlation_request(interval_arg, duration_arg, fit_from_arg, fit_to_arg, "transport");
    request.fit_to_mean_free_times = kTransportFitMeanFreeTimes;  // as analysis.transport's
    return visit([&](auto& s) {
      const auto m = advancing([&] { return measure_transport(s, request, python_keeps_going); });
      using T = typename std::decay_t<decltype(*m.transport)>;
      const T& t = *m.transport;
      py::dict out;
      span_into(out, m.span, t.samples(), t.first_time(), t.last_time());
      out["temperature"] = t.temperature();
      out["volume"] = t.volume();
      const char* names[3] = {"shear_viscosity", "bulk_viscosity", "thermal_conductivity"};
      for (int g = 0; g < 3; ++g) {
        const double scale = t.scale(g);
        const bool none = g == T::kHeatGroup && !m.no_conductivity.empty();
        const auto& eh = m.einstein_helfand[g];
        const auto& gk = m.green_kubo[g];
        const double nan = std::nan("");
        const auto value = [&](const auto& fit, double of) {
          return none || !fit ? nan : of / scale;
        };
        py::dict c;
        c["value"] = value(eh, eh ? eh->coefficient : nan);
        c["stderr"] = value(eh, eh ? eh->stderr_ : nan);
        c["stderr_epochs"] = value(eh, eh ? eh->epoch_stderr : nan);
        c["stderr_components"] = value(eh, eh ? eh->particle_stderr : nan);
        c["lags_fitted"] = eh && !none ? eh->lags : 0;
        c["epochs_fitted"] = eh && !none ? eh->epochs : 0;
        c["green_kubo"] = value(gk, gk ? gk->coefficient : nan);
        c["green_kubo_stderr"] = value(gk, gk ? gk->stderr_ : nan);
        c["why"] = none ? py::object(py::str(m.no_conductivity)) : py::object(py::none());
        out[names[g]] = c;
      }
      const auto rows_dict = [](const std::vector<typename T::Row>& rows,
                                const std::array<const char*, 3>& value_names) {
        std::vector<double> lag;
        std::vector<std::uint64_t> origins;
        std::array<std::vector<double>, 3> value, coefficient;
        for (const auto& r : rows) {
          lag.push_back(r.lag);
          origins.push_back(r.origins);
          for (int g = 0; g < 3; ++g) {
            value[g].push_back(r.value[g]);
            coefficient[g].push_back(r.coefficient[g]);
          }
        }
        py::dict d;
        d["lag"] = array_of(lag);
        d["origins"] = array_of(origins);
        const char* coefficient_names[3] = {"shear_viscosity", "bulk_viscosity",
                                            "thermal_conductivity"};
        for (int g = 0; g < 3; ++g) {
          d[value_names[g]] = array_of(value[g]);
          d[coefficient_names[g]] = array_of(coefficient[g]);
        }
        return d;
      };
      const double from = m.span.fit_from, to = m.span.fit_to;
      out["helfand"] =
          rows_dict(t.helfand_rows(from, to), {"shear_moment", "bulk_moment", "heat_moment"});
      out["green_kubo"] = rows_dict(t.green_kubo_rows(from, to),
                                    {"shear_flux_acf", "bulk_flux_acf", "heat_flux_acf"});
      if (!m.mass_moment_species.empty()) {
        py::dict beta;
        for (std::size_t k = 0; k < m.mass_moment_species.size(); ++k) {
          beta[py::str(m.mass_moment_species[k])] =
              m.heat_projection ? m.heat_projection->beta[k] : std::nan("");
        }
        py::dict d;
        d["energy_per_mass"] = beta;
        d["removed_fraction"] = m.heat_projection ? m.heat_projection->removed : std::nan("");
        d["frame"] = kMassMomentFrame;
        out["thermal_conductivity"]["interdiffusion"] = d;
      }
      return out;
    });
  }

  // Z and P over `duration` of simulated time from now, rows every `interval` (None: a 64th
  // of the duration) for the blocked error, as summary.json's compressibility and pressure.
  py::dict pressure(const py::object& duration_arg, const py::object& interval_arg) {
    CorrelationRequest request;
    request.duration = positive_from(duration_arg, "pressure: duration");
    request.interval = interval_arg.is_none() ? request.duration / 64.0
                                              : positive_from(interval_arg, "pressure: interval");
    if (request.interval > request.duration) {
      throw InputError(fmt::format(
          "pressure: interval ({}) must not exceed the duration ({}): the error needs rows",
          request.interval, request.duration));
    }
    return visit([&](auto& s) {
      const PressureMeasurement m =
          advancing([&] { return measure_pressure(s, request, python_keeps_going); });
      py::dict out;
      out["Z"] = m.compressibility.mean;
      out["Z_stderr"] = m.compressibility.stderr_;
      out["Z_stderr_reliable"] = m.undefined.empty() && m.compressibility.reliable;
      out["pressure"] = m.pressure;
      out["pressure_stderr"] = m.pressure_stderr;
      out["temperature"] = m.temperature;
      out["rows"] = m.compressibility.samples;
      out["interval"] = request.interval;
      out["start_time"] = m.span.start_time;
      out["end_time"] = m.span.end_time;
      out["collisions"] = m.span.collisions;
      out["mean_free_time"] = m.span.mean_free_time;
      out["completed"] = m.span.completed;
      out["why"] = m.undefined.empty() ? py::object(py::none()) : py::object(py::str(m.undefined));
      const auto d = static_cast<std::size_t>(dimension_of(s));
      out["pressure_tensor"] =
          m.tensor
              ? py::object(matrix_of(
                    d, d, [&](std::size_t a, std::size_t b) { return (*m.tensor)[a * d + b]; }))
              : py::object(py::none());
      if (m.shear_stress) {
        py::dict shear;
        shear["shear_rate"] = m.shear_rate;
        shear["shear_stress"] = m.shear_stress->mean;
        shear["shear_stress_stderr"] = m.shear_stress->stderr_;
        shear["viscosity"] = -m.shear_stress->mean / m.shear_rate;
        shear["viscosity_stderr"] = m.shear_stress->stderr_ / std::abs(m.shear_rate);
        shear["samples"] = m.shear_stress->samples;
        out["shear"] = shear;
      }
      return out;
    });
  }

  double virial() const {
    return visit([](const auto& s) { return s.virial(); });
  }
  py::dict energies() const {
    return visit([](const auto& s) {
      const auto e = s.energies();
      py::dict out;
      out["kinetic"] = e.kinetic;
      out["rotational"] = e.rotational;
      out["potential"] = e.potential;
      out["field"] = e.field;
      out["dissipated"] = e.dissipated;
      out["work_by_walls"] = e.work_by_walls;
      out["work_by_driving"] = e.work_by_driving;
      out["work_by_shear"] = e.work_by_shear;
      out["taken_out"] = e.taken_out;
      return out;
    });
  }
  py::array_t<double> momentum() const {
    return visit([](const auto& s) {
      const auto p = s.momentum();
      return py::array_t<double>(static_cast<py::ssize_t>(p.size()), p.data());
    });
  }
  double max_overlap() const {
    return visit([](const auto& s) { return s.max_overlap(); });
  }
  std::string integrator() const {
    return visit([](const auto& s) { return std::string(s.integrator().name()); });
  }

  std::string repr() const {
    return visit([](const auto& s) {
      return fmt::format("<kairos.Simulation ({}): {} particles in {}D, t = {:.6g}, {} collisions>",
                         s.integrator().name(), s.size(), dimension_of(s), s.time(),
                         s.collisions());
    });
  }
  void save(const fs::path& path) const {
    visit([&](const auto& s) { s.save(path); });
  }

 private:
  static CorrelationRequest correlation_request(const py::object& interval,
                                                const py::object& duration,
                                                const py::object& fit_from,
                                                const py::object& fit_to,
                                                const std::string& where) {
    CorrelationRequest r;
    r.interval = positive_from(interval, where + ": interval",
                               "half the Enskog mean free time now, as analysis.msd_interval = 0");
    r.interval_name = "interval";
    r.duration = non_negative_from(duration, where + ": duration");
    std::tie(r.fit_from, r.fit_to) = fit_window_from(fit_from, fit_to, where);
    return r;
  }
  template <int D>
  static int dimension_of(const Simulation<D>&) {
    return D;
  }
  std::variant<std::unique_ptr<Simulation<2>>, std::unique_ptr<Simulation<3>>> sim_;
  std::atomic<bool> busy_{false};
  std::atomic<bool> in_callback_{false};  // an advance's callback runs (no nested advance)
};

// kairos.Correlator: analysis/msd.hpp's multiple-tau correlator fed by the user, with 1, 2 or
// 3 components per particle (fixed by the first sample).
template <class C>
struct CorrelatorDimension;
template <int D>
struct CorrelatorDimension<MsdCorrelator<D>> {
  static constexpr int value = D;
};

class PyCorrelator {
 private:
  static constexpr std::array<const char*, 3> kStatistics = {"displacement", "product", "flux"};
  template <int D>
  MsdCorrelator<D> make() const {
    return MsdCorrelator<D>(group_, groups_, interval_,
                            static_cast<typename MsdCorrelator<D>::Statistic>(statistic_),
                            max_levels_);
  }
  void start() {
    if (dimension_ == 1) correlator_.emplace(make<1>());
    if (dimension_ == 2) correlator_.emplace(make<2>());
    if (dimension_ == 3) correlator_.emplace(make<3>());
  }
  // f(correlator); before the first sample, of an empty one.
  template <class F>
  auto with(F&& f) const {
    if (correlator_) return std::visit([&](const auto& c) { return f(c); }, *correlator_);
    return f(make<1>());
  }
  double sampled() const {
    const std::uint64_t n = samples();
    return n > 1 ? static_cast<double>(n - 1) * interval_ : 0.0;
  }

 public:
  PyCorrelator(const py::object& interval, const py::object& groups, const py::object& statistic,
               const py::object& max_levels) {
    interval_ = positive_from(interval, "Correlator: interval");
    if (!py::isinstance<py::str>(statistic)) {
      throw py::type_error(
          fmt::format("Correlator: statistic must be 'displacement', 'product' or 'flux', not {}",
                      type_name(statistic)));
    }
    const auto name = statistic.cast<std::string>();
    const auto known = std::find(kStatistics.begin(), kStatistics.end(), name);
    if (known == kStatistics.end()) {
      throw InputError(fmt::format(
          "Correlator: statistic must be 'displacement', 'product' or 'flux', not '{}'", name));
    }
    statistic_ = static_cast<int>(known - kStatistics.begin());
    const long long levels = integer_from(max_levels, "Correlator: max_levels");
    if (levels < 1 || levels > 48) {
      throw InputError(
          fmt::format("Correlator: max_levels must be between 1 and 48, not {}", levels));
    }
    max_levels_ = static_cast<int>(levels);
    if (!groups.is_none()) set_groups(groups);
  }

  void add(const py::object& x) {
    const py::array_t<double> a = float_array(x, "Correlator.add: x");
    if (a.ndim() != 1 && a.ndim() != 2) {
      throw InputError(fmt::format(
          "Correlator.add: x must be an (n, d) array (or (n,) for d = 1), not {}-dimensional",
          a.ndim()));
    }
    const auto n = static_cast<std::size_t>(a.shape(0));
    const int d = a.ndim() == 1 ? 1 : static_cast<int>(a.shape(1));
    if (n == 0 || d < 1 || d > 3) {
      throw InputError(fmt::format(
          "Correlator.add: x has shape ({}, {}): at least one particle, with d = 1, 2 or 3 "
          "components",
          n, d));
    }
    if (!correlator_) {
      if (group_.empty()) {
        group_.assign(n, 0u);
        groups_ = 1;
      } else if (n != group_.size()) {
        throw InputError(
            fmt::format("Correlator.add: x has {} particles, groups gives {}", n, group_.size()));
      }
      dimension_ = d;
      start();
    } else if (n != group_.size() || d != dimension_) {
      throw InputError(
          fmt::format("Correlator.add: x has shape ({}, {}), the earlier samples ({}, {})", n, d,
                      group_.size(), dimension_));
    }
    const double* data = a.data();
    for (std::size_t k = 0; k < n * static_cast<std::size_t>(d); ++k) {
      if (!std::isfinite(data[k]))
        throw InputError("Correlator.add: x holds NaN or infinite values");
    }
    std::visit(
        [&](auto& c) {
          constexpr int kD = CorrelatorDimension<std::decay_t<decltype(c)>>::value;
          std::vector<Vec<kD>> sample(n);
          for (std::size_t i = 0; i < n; ++i)
            for (int k = 0; k < kD; ++k) sample[i][k] = data[i * kD + k];
          c.add(sample);
        },
        *correlator_);
  }

  py::dict lags() const {
    return with([&](const auto& c) { return lags_dict(c, statistic_ == 0, "mean"); });
  }

  py::dict diffusion(const py::object& from_arg, const py::object& to_arg,
                     const py::object& drift_arg, const py::object& span_arg) const {
    if (statistic_ != 0) {
      throw InputError(fmt::format(
          "Correlator.diffusion: the slope of a statistic='displacement' correlator; this one's "
          "statistic is '{}' (its integral: green_kubo())",
          kStatistics[statistic_]));
    }
    auto [from, to] = fit_window_from(from_arg, to_arg, "Correlator.diffusion");
    std::tie(from, to) = correlation_fit_window(sampled(), from, to, std::nan(""));
    const double span =
        span_arg.is_none() ? 0.0 : non_negative_from(span_arg, "Correlator.diffusion: span");
    return with([&](const auto& c) {
      constexpr int kD = CorrelatorDimension<std::decay_t<decltype(c)>>::value;
      const auto drift = per_group<kD>(drift_arg, "Correlator.diffusion: drift");
      py::dict out =
          fits_dict(drift.empty() ? c.diffusion(from, to) : c.diffusion(from, to, drift, span));
      out["fit_from"] = from;
      out["fit_to"] = to;
      return out;
    });
  }

  py::dict green_kubo(const py::object& to_arg, const py::object& mean_arg) const {
    if (statistic_ == 0) {
      throw InputError(
          "Correlator.green_kubo: the integral of a statistic='product' or 'flux' correlator; "
          "this one's statistic is 'displacement' (its slope: diffusion())");
    }
    double to = positive_from(to_arg, "Correlator.green_kubo: to", "automatic");
    to = correlation_fit_window(sampled(), 0.0, to, std::nan("")).second;
    return with([&](const auto& c) {
      constexpr int kD = CorrelatorDimension<std::decay_t<decltype(c)>>::value;
      const auto mean = per_group<kD>(mean_arg, "Correlator.green_kubo: mean");
      py::dict out = fits_dict(mean.empty() ? c.green_kubo(to) : c.green_kubo(to, mean));
      out["to"] = to;
      return out;
    });
  }

  std::uint64_t samples() const {
    return with([](const auto& c) { return c.samples(); });
  }
  double interval() const { return interval_; }
  std::string statistic() const { return kStatistics[statistic_]; }
  py::object dimension() const {
    return correlator_ ? py::object(py::int_(dimension_)) : py::object(py::none());
  }
  py::object particles() const {
    return group_.empty() ? py::object(py::none()) : py::object(py::int_(group_.size()));
  }
  std::uint32_t groups() const { return groups_; }
  std::size_t bytes() const {
    return with([](const auto& c) { return c.bytes(); });
  }
  std::string repr() const {
    return fmt::format("<kairos.Correlator: statistic '{}', interval {:.6g}, {} samples>",
                       statistic(), interval_, samples());
  }

 private:
  // groups: one non-negative integer per particle, every group 0 .. G - 1 with a particle.
  void set_groups(const py::object& groups) {
    const py::array_t<double> a = float_array(groups, "Correlator: groups");
    if (a.ndim() != 1 || a.shape(0) == 0) {
      throw InputError(
          "Correlator: groups must be a 1-D sequence of group indices (0, 1, ...), "
          "one per particle");
    }
    std::uint32_t count = 0;
    for (py::ssize_t i = 0; i < a.shape(0); ++i) {
      const double g = a.at(i);
      if (!(g >= 0.0) || g != std::floor(g) || g > 1e6) {
        throw InputError(fmt::format(
            "Correlator: groups[{}] = {}: group indices are integers 0, 1, ... (below 10^6)", i,
            g));
      }
      group_.push_back(static_cast<std::uint32_t>(g));
      count = std::max(count, group_.back() + 1);
    }
    std::vector<bool> used(count, false);
    for (const std::uint32_t g : group_) used[g] = true;
    for (std::uint32_t g = 0; g < count; ++g) {
      if (!used[g]) {
        throw InputError(fmt::format(
            "Correlator: groups has no particle in group {} (number the groups 0 .. {})", g,
            count - 1));
      }
    }
    groups_ = count;
  }

  // None (nothing), or a (groups, d) array: one vector per group (a drift, a mean).
  template <int D>
  std::vector<Vec<D>> per_group(const py::object& value, const std::string& name) const {
    if (value.is_none()) return {};
    const py::array_t<double> a = float_array(value, name);
    const bool shaped = (a.ndim() == 2 && a.shape(0) == groups_ && a.shape(1) == D) ||
                        (a.ndim() == 1 && D == 1 && a.shape(0) == groups_);
    if (!shaped) {
      throw InputError(
          fmt::format("{} must have shape ({}, {}): one vector per group", name, groups_, D));
    }
    std::vector<Vec<D>> out(groups_);
    for (std::uint32_t g = 0; g < groups_; ++g)
      for (int k = 0; k < D; ++k) out[g][k] = a.data()[g * D + k];
    for (const Vec<D>& v : out)
      for (int k = 0; k < D; ++k)
        if (!std::isfinite(v[k])) throw InputError(name + " holds NaN or infinite values");
    return out;
  }

  // Any array-like of numbers as a C-contiguous float64 array; TypeError naming it otherwise.
  static py::array_t<double> float_array(const py::object& value, const std::string& name) {
    if (py::isinstance<py::str>(value) || py::isinstance<py::bytes>(value)) {
      throw py::type_error(
          fmt::format("{} must be an array of numbers, not {}", name, type_name(value)));
    }
    try {
      return py::module_::import("numpy").attr("ascontiguousarray")(value, "float64");
    } catch (const py::error_already_set&) {
      throw py::type_error(
          fmt::format("{} must be an array of numbers, not {}", name, type_name(value)));
    }
  }

  double interval_ = 0.0;
  int statistic_ = 0;  // index in kStatistics (MsdCorrelator's Statistic)
  int max_levels_ = 40;
  std::vector<std::uint32_t> group_;
  std::uint32_t groups_ = 1;
  int dimension_ = 0;
  std::optional<std::variant<MsdCorrelator<1>, MsdCorrelator<2>, MsdCorrelator<3>>> correlator_;
};

}  // namespace
}  // namespace kairos

PYBIND11_MODULE(kairos, m) {
  using kairos::PyCorrelator;
  using kairos::PySimulation;
  m.doc() =
      "Kairos, event-driven particle dynamics: kairos.run (the `kairos run` command), "
      "kairos.Simulation (a simulation in memory, its state as NumPy arrays, its analyses), "
      "kairos.Correlator (the multiple-tau correlator), kairos.sweep and "
      "kairos.replica_exchange (grids of runs and parallel tempering). docs/python.md.";
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
        // The call as the provenance's command line: its arguments as Python spells them (TOML
        // text given inline as <TOML text>).
        const bool inline_text = py::isinstance<py::str>(config) &&
                                 config.cast<std::string>().find('\n') != std::string::npos;
        std::string call = "kairos.run(" + (inline_text ? std::string("<TOML text>")
                                                        : py::repr(config).cast<std::string>());
        for (const auto& [name, value] :
             {std::pair<const char*, const py::object*>{"output", &output_arg},
              {"set", &set},
              {"restart", &restart_arg}}) {
          if (!value->is_none())
            call += fmt::format(", {}={}", name, py::repr(*value).cast<std::string>());
        }
        if (overwrite) call += ", overwrite=True";
        call += ")";
        const kairos::RunOutcome outcome = [&] {
          kairos::SigintStopsRun sigint;
          const kairos::ScopedStopDeadline setup_limit(c.run.max_wall_seconds);
          py::gil_scoped_release release;  // the run is C++ throughout
          kairos::RunOptions options;
          options.overwrite = overwrite;
          options.command_line = call;
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

  kairos::bind_runners(m);  // kairos.sweep, kairos.replica_exchange (runner_bindings.cpp)

  py::class_<PySimulation>(m, "Simulation",
                           "A simulation in memory: the integrator of `kairos run` (the event "
                           "engine, or the DEM with run.integrator = \"dem\") started from the "
                           "same configuration (bit-identical trajectory), advanced on request, "
                           "without output files.")
      .def(py::init<const py::object&, const py::object&, const py::object&, const py::object&,
                    const py::object&>(),
           py::arg("config"), py::arg("set") = py::none(), py::arg("restart") = py::none(),
           py::arg("images") = true, py::arg("helfand") = false,
           "config: a TOML file's path, or TOML text; set: 'key=value' overrides; restart: a "
           "restart file to continue from; images: keep image counters (4 D bytes per particle) "
           "for unwrapped_positions(), images() and msd(); helfand: keep the Helfand moments "
           "for helfand_moments() and transport() (a conservative periodic system).")
      .def("advance", &PySimulation::advance, py::arg("time") = py::none(),
           py::arg("events") = py::none(), py::arg("collisions") = py::none(),
           py::arg("every") = py::none(), py::arg("callback") = py::none(),
           "Advances to simulated time `time` (exactly; no event needs to happen then), or by "
           "`events` events, or by `collisions` collisions (one of the three). With every= and "
           "callback=, calls callback(sim) at each multiple of `every` on the way (in the "
           "target's unit: simulated time, or events / collisions from now); the callback may "
           "read or change the state, and returning False stops the advance there. Returns False "
           "if no event was left before the target or the callback stopped it.")
      .def("positions", &PySimulation::positions,
           "Positions at the present time, an (N, D) array, wrapped into the periodic box.")
      .def("velocities", &PySimulation::velocities, "Velocities at the present time, (N, D).")
      .def("set_velocities", &PySimulation::set_velocities, py::arg("velocities"),
           "Gives every particle a new velocity now ((N, D), the numbering of positions()): the "
           "run goes on as one started with them. Refused (InputError) for a fixed grain given "
           "a velocity, soft spheres, sleeping particles or helfand=True.")
      .def("set_positions", &PySimulation::set_positions, py::arg("positions"),
           "Moves every particle to a new place now ((N, D), the numbering of positions(); "
           "wrapped into the periodic box). Velocities and the clock stay; every event is "
           "predicted anew. InputError naming the pair for an overlap, or the engine's message "
           "for a wall or a bond the new places break.")
      .def("set_species", &PySimulation::set_species, py::arg("species"),
           "Gives particles new species now ((N,) indices into species_names; the radius and "
           "mass of the configuration's species of that name). InputError for an overlap the "
           "new sizes make, a species the configuration lacks, or a change to or from a fixed "
           "species.")
      .def("set_thermostat_temperature", &PySimulation::set_thermostat_temperature,
           py::arg("temperature"),
           "[driving] kind = \"andersen\": the thermostat's temperature from now on (what save() "
           "stores too); the velocities are not changed.")
      .def("masses", &PySimulation::masses)
      .def("radii", &PySimulation::radii)
      .def("species", &PySimulation::species, "Species index of each particle.")
      .def_property_readonly("species_names", &PySimulation::species_names)
      .def_property_readonly("box", &PySimulation::box, "Box edges, (D,).")
      .def_property_readonly("dimension", &PySimulation::dimension)
      .def_property_readonly("time", &PySimulation::time)
      .def_property_readonly("events", &PySimulation::events)
      .def_property_readonly("collisions", &PySimulation::collisions)
      .def_property_readonly("virial", &PySimulation::virial,
                             "The collisional virial W = sum r_ij . J_ij since the state's start "
                             "(the DEM: the time integral of sum r_ij . F_ij).")
      .def_property_readonly("integrator", &PySimulation::integrator, "\"event\" or \"dem\".")
      .def("energies", &PySimulation::energies,
           "The energies now and the work and dissipation since the state's start: kinetic, "
           "rotational, potential, field (gravity), dissipated, work_by_walls, work_by_driving, "
           "work_by_shear, taken_out (docs/python.md).")
      .def("momentum", &PySimulation::momentum, "The total momentum, (D,).")
      .def("max_overlap", &PySimulation::max_overlap,
           "The largest overlap of any pair now (0 for hard particles up to round-off).")
      .def("pressure", &PySimulation::pressure, py::arg("duration"),
           py::arg("interval") = py::none(),
           "Advances by duration; Z and the pressure over it as summary.json gives them, with "
           "the blocked error over rows interval apart (None: a 64th of the duration).")
      .def("__len__", &PySimulation::size)
      .def("kinetic_energy", &PySimulation::kinetic_energy)
      .def("temperature", &PySimulation::temperature,
           "kT as thermo.tsv gives it: D (N - 1) degrees of freedom; under shear, of the "
           "velocities relative to the flow.")
      .def("potential_energy", &PySimulation::potential_energy,
           "Of the stepped potentials, or the elastic energy of soft contacts in progress.")
      .def("compression", &PySimulation::compression,
           "The compression that made the start state ([compress], or a random start denser "
           "than insertion reaches) as summary.json's `compression` (contacts included) with "
           "`history`: compress.tsv's columns as arrays. None if the start was not compressed.")
      .def("walls_with_mass", &PySimulation::walls_with_mass,
           "The walls with mass now (boundary.wall.mass): one dict each, face, position (of its "
           "plane along its axis), speed and energy, as thermo.tsv's columns, and mass, force "
           "and pressure (summary.json's), a container's spring work.")
      .def("outlet", &PySimulation::outlet,
           "An outlet's tally since the start ([boundary.outlet]): passes, mass, energy_taken, "
           "waiting (the DEM's particles waiting to pass; None for the event engine); None "
           "without an outlet.")
      .def("__repr__", &PySimulation::repr)
      .def("save", &PySimulation::save, py::arg("path"),
           "Writes a restart file (atomically) that `kairos run --restart` continues.")
      .def_property_readonly("tracks_images", &PySimulation::tracks_images,
                             "Image counters are kept (images=True, output.trajectory, "
                             "analysis.msd, or a restart state that carried them).")
      .def_property_readonly("tracks_helfand", &PySimulation::tracks_helfand,
                             "The Helfand moments are kept (helfand=True or analysis.transport).")
      .def("unwrapped_positions", &PySimulation::unwrapped_positions,
           "Positions at the present time unwrapped through the periodic faces, (N, D).")
      .def("images", &PySimulation::images,
           "Periodic images of positions(), (N, D) int32: positions() + images() * box is the "
           "unwrapped position.")
      .def("rdf", &PySimulation::rdf, py::arg("bins") = 200, py::arg("r_max") = py::none(),
           "g(r) of the present state per species pair, as rdf.tsv after one sample: a dict of "
           "r, g (per pair), g_all, contact and sigma (per pair), ...")
      .def("structure_factor", &PySimulation::structure_factor, py::arg("k_max") = py::none(),
           "S(k) of the present state on the box's wave vectors, as sk.tsv after one sample: a "
           "dict of k, S, vectors, available, s_zero, ...")
      .def("bond_order", &PySimulation::bond_order, py::arg("cutoff") = 1.4,
           "Bond orientational order of the present state: local q4, q6 (3D) or psi6 (2D) per "
           "particle (NaN without neighbours) and the global values (q4_global, ...).")
      .def("velocity_distribution", &PySimulation::velocity_distribution,
           "The distribution of one velocity component in units of sqrt(kT/m) now, with the "
           "kurtosis, Sonine a2 and tail ratio.")
      .def("msd", &PySimulation::msd, py::arg("interval"), py::arg("duration"),
           py::arg("fit_from") = py::none(), py::arg("fit_to") = py::none(),
           py::arg("vacf") = false, py::arg("particles") = py::none(), py::arg("clock") = "auto",
           py::arg("mutual") = false,
           "ADVANCES the simulation by `duration`, sampling the unwrapped positions at the "
           "multiples of `interval` (None: automatic) as analysis.msd does; returns the MSD "
           "per species on log-spaced lags and D fitted over [fit_from, fit_to] (None: "
           "automatic), with the VACF and Green-Kubo D if vacf=True. Follows every moving "
           "particle, or every k-th so that at most `particles` are (as analysis.msd_particles). "
           "clock: \"time\", \"collisions\" (interval, duration, lags and window in collisions "
           "per particle) or \"auto\" (collisions for a freely cooling gas), as "
           "analysis.msd_time. mutual=True: the interdiffusion coefficients of a mixture as "
           "analysis.mutual_diffusion.")
      .def("helfand_moments", &PySimulation::helfand_moments,
           "The Helfand moments now (needs helfand=True): kinetic_stress, virial, stress (D, D), "
           "energy_kinetic, energy_collisional, energy (D,).")
      .def("transport", &PySimulation::transport, py::arg("interval"), py::arg("duration"),
           py::arg("fit_from") = py::none(), py::arg("fit_to") = py::none(),
           "ADVANCES the simulation by `duration`, sampling the Helfand moments at the "
           "multiples of `interval` (None: automatic) as analysis.transport does; returns the "
           "shear and bulk viscosities and the thermal conductivity (Einstein-Helfand, "
           "Green-Kubo beside) with their errors, and the per-lag tables.");

  py::class_<PyCorrelator>(m, "Correlator",
                           "The multiple-tau correlator of analysis.msd (log-spaced lags, many "
                           "time origins, bounded memory) fed with your own samples.")
      .def(py::init<const py::object&, const py::object&, const py::object&, const py::object&>(),
           py::arg("interval"), py::arg("groups") = py::none(),
           py::arg("statistic") = "displacement", py::arg("max_levels") = 40,
           "interval: the time between samples; groups: one group index per particle (None: "
           "one group); statistic: 'displacement' (<|x(t+lag) - x(t)|^2>), 'product' "
           "(<x(t+lag).x(t)>) or 'flux' (<J(t+lag).J(t)> of the fluxes J of the samples).")
      .def("add", &PyCorrelator::add, py::arg("x"),
           "The next sample, `interval` after the previous one: an (n, d) array (d = 1, 2, 3; "
           "(n,) for d = 1).")
      .def("lags", &PyCorrelator::lags,
           "The lags with at least one origin: lag, origins, mean (lags, groups) and for "
           "displacements non_gaussian.")
      .def("diffusion", &PyCorrelator::diffusion, py::arg("fit_from") = py::none(),
           py::arg("fit_to") = py::none(), py::arg("drift") = py::none(),
           py::arg("span") = py::none(),
           "D per group from the slope of the mean-square displacement = 2 d D lag over the "
           "lags in [fit_from, fit_to], with standard errors (NaN: fewer than 3 lags).")
      .def("green_kubo", &PyCorrelator::green_kubo, py::arg("to") = py::none(),
           py::arg("mean") = py::none(),
           "(1/d) integral_0^to of the correlation per group, with standard errors.")
      .def_property_readonly("samples", &PyCorrelator::samples)
      .def_property_readonly("interval", &PyCorrelator::interval)
      .def_property_readonly("statistic", &PyCorrelator::statistic)
      .def_property_readonly("dimension", &PyCorrelator::dimension)
      .def_property_readonly("particles", &PyCorrelator::particles)
      .def_property_readonly("groups", &PyCorrelator::groups)
      .def_property_readonly("bytes", &PyCorrelator::bytes)
      .def("__repr__", &PyCorrelator::repr);
}

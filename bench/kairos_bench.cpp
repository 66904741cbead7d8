// Benchmark driver: hard-sphere / hard-disk fluids started on a lattice (or by random insertion),
// equilibrated, then timed over a fixed number of collisions per particle through the engine
// alone. Prints the machine, the date and one table row per case (Markdown or TSV).
//
//   kairos_bench                          # the foundation cases (bench/README.md)
//   kairos_bench --suite full             # the performance issue's matrix (bench/README.md)
//   kairos_bench --suite quick            # a few seconds: smoke test
//   kairos_bench --particles 32000 --eta 0.45 --sizes mono,1.4 --queue calendar,heap --repeat 3
//   kairos_bench --suite granular         # inelastic gas, vibrated bed, settling pile
//   kairos_bench --case gas --dimension 3 # one granular case (granular_cases.hpp)
//   kairos_bench --suite stepped          # square well and stepped Lennard-Jones vs hard spheres
//   kairos_bench --case sw --scan vector,scalar   # one stepped case (stepped_cases.hpp)
//   kairos_bench --suite soft             # soft spheres: event-driven (mapped) vs DEM vs hard
//   kairos_bench --case dashpot --eta 0.05 --contact-ratio 100   # one soft case (soft_cases.hpp)
//
// Cases given several queues are run interleaved (A B A B ...) so that machine noise hits
// every variant alike; the best of the repeats is reported with the spread.
//
// Only the engine's public surface is used: EventEngine<D, Queue>(ParticleSystem<D>), step(),
// counters(), bytes_per_particle(), size(), and to_particle_system(make_initial_state(...)).
#include <sys/utsname.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <exception>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "core/error.hpp"
#include "engine/candidate_scan.hpp"
#include "engine/event_engine.hpp"
#include "granular_cases.hpp"
#include "init/initial_state.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"
#include "scheduler/tournament_tree_queue.hpp"
#include "soft_cases.hpp"
#include "stepped_cases.hpp"

#ifndef KAIROS_BENCH_BUILD_TYPE
#define KAIROS_BENCH_BUILD_TYPE "unknown"
#endif
#ifndef KAIROS_BENCH_CXX_FLAGS
#define KAIROS_BENCH_CXX_FLAGS ""
#endif

namespace {

using namespace kairos;
using Clock = std::chrono::steady_clock;

// Bad command-line input: one line on stderr, exit code 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// ---------------------------------------------------------------------------------------------
// Cases and measurements

struct Case {
  int dimension = 3;
  std::uint64_t particles = 32000;
  double eta = 0.45;
  double size_ratio = 1.0;  // > 1: 50:50 bidisperse mixture of diameters 1 and size_ratio
  double equilibrate = 20;  // untimed collisions per particle
  double timed = 100;       // timed collisions per particle
};

struct Counts {
  std::uint64_t events = 0, collisions = 0, crossings = 0, stale = 0;
};

Counts counts_of(const EventCounters& c) {
  return {c.events, c.collisions, c.cell_crossings, c.stale_events};
}

Counts operator-(const Counts& a, const Counts& b) {
  return {a.events - b.events, a.collisions - b.collisions, a.crossings - b.crossings,
          a.stale - b.stale};
}

struct Run {
  Counts timed;        // over the timed part
  Counts total;        // the engine's totals at the end (construction + equilibration + timed)
  double wall = 0;     // timed part, seconds
  double eq_wall = 0;  // engine construction (predicting every event) + equilibration, seconds
  double bytes_per_particle = 0;  // whatever type the engine reports it in

  double per_second(std::uint64_t n) const { return static_cast<double>(n) / wall; }
  double per_collision(std::uint64_t n) const {
    return timed.collisions == 0 ? 0.0
                                 : static_cast<double>(n) / static_cast<double>(timed.collisions);
  }
  double collisions_per_second() const { return per_second(timed.collisions); }
};

// Steps until the engine has done `target` collisions in total; throws if it stops making events.
template <class Engine>
void run_until(Engine& engine, std::uint64_t target) {
  while (engine.counters().collisions < target) {
    const std::uint64_t before = engine.counters().events;
    engine.step();
    if (engine.counters().events == before) {
      throw std::runtime_error("the engine stopped producing events");
    }
  }
}

// Collisions for `per_particle` collisions per particle: each collision involves two particles.
std::uint64_t collisions_for(double per_particle, std::size_t n) {
  return static_cast<std::uint64_t>(per_particle * static_cast<double>(n) / 2.0);
}

template <int D, class Queue>
Run measure(const ParticleSystem<D>& start, double equilibrate, double timed,
            EngineOptions options) {
  const auto t_begin = Clock::now();
  EventEngine<D, Queue> engine(start, StartMode::kPredict, options);
  run_until(engine, collisions_for(equilibrate, engine.size()));
  const Counts c0 = counts_of(engine.counters());
  const auto t0 = Clock::now();
  run_until(engine, c0.collisions + collisions_for(timed, engine.size()));
  const auto t1 = Clock::now();
  Run r;
  r.total = counts_of(engine.counters());
  r.timed = r.total - c0;
  r.wall = std::chrono::duration<double>(t1 - t0).count();
  r.eq_wall = std::chrono::duration<double>(t0 - t_begin).count();
  r.bytes_per_particle = static_cast<double>(engine.bytes_per_particle());
  return r;
}

// A queue name, with the suffix kFullScans when every crossing rescans all neighbours
// (--crossings full) and a list-walk suffix (--list-gather).
constexpr std::string_view kFullScans = " full-scan";
constexpr std::string_view kScalarWalk = " scalar-walk";
constexpr std::string_view kVectorGather = " vector-gather";
constexpr std::string_view kGatherLoads = " gather-loads";
constexpr std::string_view kRowLoads = " row-loads";

// Whether name ends with suffix; if so, takes it off.
bool strip_suffix(std::string_view& name, std::string_view suffix) {
  if (!name.ends_with(suffix)) return false;
  name.remove_suffix(suffix.size());
  return true;
}

// Strips the variant suffixes off a queue name into options (the reverse order of with_variants).
std::string_view strip_variants(std::string_view queue, EngineOptions& options) {
  if (strip_suffix(queue, kGatherLoads)) options.record_loads = RecordLoads::kGather;
  if (strip_suffix(queue, kRowLoads)) options.record_loads = RecordLoads::kRows;
  if (strip_suffix(queue, kScalarWalk)) options.list_gather = ListGather::kScalar;
  if (strip_suffix(queue, kVectorGather)) options.list_gather = ListGather::kVector;
  if (strip_suffix(queue, kFullScans)) options.incremental_crossings = false;
  return queue;
}

// Every queue name with every value of a variant option: the name plus the value's suffix (none
// for a value without one: the default).
std::vector<std::string> with_variants(
    const std::vector<std::string>& queues, const std::vector<std::string>& values,
    const std::vector<std::pair<std::string_view, std::string_view>>& suffixes) {
  std::vector<std::string> out;
  for (const std::string& q : queues) {
    for (const std::string& v : values) {
      std::string name = q;
      for (const auto& [value, suffix] : suffixes)
        if (v == value) name += suffix;
      out.push_back(name);
    }
  }
  return out;
}

template <int D>
Run measure_queue(std::string_view queue, const ParticleSystem<D>& s, const Case& c) {
  EngineOptions options;
  queue = strip_variants(queue, options);
  if (queue == "heap") return measure<D, BinaryHeapQueue>(s, c.equilibrate, c.timed, options);
  if (queue == "tree") return measure<D, TournamentTreeQueue>(s, c.equilibrate, c.timed, options);
  return measure<D, CalendarQueue>(s, c.equilibrate, c.timed, options);
}

std::string default_lattice(int dimension) {
  return dimension == 3 ? "fcc" : "hex";
}

// The starting state. Monodisperse: the fcc / hex lattice. Mixtures: random insertion (species
// sorted spatially by the generator); where the generator refuses random insertion (too dense)
// the default lattice with the species shuffled over its sites, which the equilibration melts.
template <int D>
ParticleSystem<D> make_system(const Case& c, std::string& start) {
  SystemConfig sys;
  sys.dimension = D;
  sys.particles = c.particles;
  sys.packing_fraction = c.eta;
  sys.lattice = default_lattice(D);
  sys.seed = 1;
  if (c.size_ratio > 1.0) {
    sys.species = {{"A", 1.0, 1.0, 0.5}, {"B", c.size_ratio, 1.0, 0.5}};
    sys.lattice = "random";
    try {
      std::mt19937_64 rng(sys.seed);
      auto s = to_particle_system<D>(make_initial_state<D>(sys, rng));
      start = "random";
      return s;
    } catch (const InputError& random_error) {
      sys.lattice = default_lattice(D);
      try {
        std::mt19937_64 rng(sys.seed);
        auto s = to_particle_system<D>(make_initial_state<D>(sys, rng));
        start = sys.lattice;
        return s;
      } catch (const InputError& lattice_error) {
        throw InputError(fmt::format("random insertion: {}; {} lattice: {}", random_error.what(),
                                     sys.lattice, lattice_error.what()));
      }
    }
  }
  std::mt19937_64 rng(sys.seed);
  start = sys.lattice;
  return to_particle_system<D>(make_initial_state<D>(sys, rng));
}

struct Row {
  Case c;
  std::string start, queue;
  int repeats = 1;
  double setup_seconds = 0;  // building the initial state (once per case)
  Run best;
  double spread = 0;  // (best - worst) / best collision rate
};

template <int D>
std::vector<Row> run_case_d(const Case& c, const std::vector<std::string>& queues, int repeat) {
  const auto t0 = Clock::now();
  std::string start;
  const ParticleSystem<D> system = make_system<D>(c, start);
  const double setup = std::chrono::duration<double>(Clock::now() - t0).count();
  std::vector<std::vector<Run>> runs(queues.size());
  for (int r = 0; r < repeat; ++r) {
    for (std::size_t q = 0; q < queues.size(); ++q) {
      runs[q].push_back(measure_queue<D>(queues[q], system, c));
    }
  }
  std::vector<Row> rows;
  for (std::size_t q = 0; q < queues.size(); ++q) {
    auto& rs = runs[q];
    std::sort(rs.begin(), rs.end(), [](const Run& a, const Run& b) {
      return a.collisions_per_second() > b.collisions_per_second();
    });
    Row row;
    row.c = c;
    row.start = start;
    row.queue = queues[q];
    row.repeats = repeat;
    row.setup_seconds = setup;
    row.best = rs.front();
    const double best = rs.front().collisions_per_second();
    row.spread = best > 0 ? (best - rs.back().collisions_per_second()) / best : 0.0;
    rows.push_back(row);
  }
  return rows;
}

std::vector<Row> run_case(const Case& c, const std::vector<std::string>& queues, int repeat) {
  return c.dimension == 2 ? run_case_d<2>(c, queues, repeat) : run_case_d<3>(c, queues, repeat);
}

// ---------------------------------------------------------------------------------------------
// Machine facts

std::string trim(std::string s) {
  const auto b = s.find_first_not_of(" \t\r\n\"");
  const auto e = s.find_last_not_of(" \t\r\n\"");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

std::string read_first_line(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return trim(line);
}

// Value of the first "key: value" / "key=value" line whose key is `key`.
std::string read_key(const std::string& path, const std::string& key, char separator) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    const auto p = line.find(separator);
    if (p != std::string::npos && trim(line.substr(0, p)) == key) return trim(line.substr(p + 1));
  }
  return {};
}

int count_cpuinfo_processors() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    if (line.rfind("processor", 0) == 0) ++n;
  }
  return n;
}

std::string cache_text() {
  std::string out;
  for (int i = 0; i < 8; ++i) {
    const std::string dir = fmt::format("/sys/devices/system/cpu/cpu0/cache/index{}/", i);
    const std::string level = read_first_line(dir + "level");
    if (level.empty()) break;
    const std::string type = read_first_line(dir + "type");
    const std::string size = read_first_line(dir + "size");
    std::string name = "L" + level;
    if (type == "Data") name += "d";
    if (type == "Instruction") name += "i";
    if (!out.empty()) out += ", ";
    out +=
        name + " " +
        (size.size() > 1 && size.back() == 'K' ? size.substr(0, size.size() - 1) + " KiB" : size);
  }
  return out.empty() ? "unknown" : out;
}

std::string compiler_text() {
#if defined(__clang__)
  return fmt::format("Clang {}", __clang_version__);
#elif defined(__GNUC__)
  return fmt::format("GCC {}", __VERSION__);
#else
  return fmt::format("{}", __VERSION__);
#endif
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", &tm);
  return buf;
}

std::vector<std::string> machine_facts() {
  std::string cpu = read_key("/proc/cpuinfo", "model name", ':');
  if (cpu.empty()) cpu = "unknown CPU";
  const int logical = count_cpuinfo_processors();
  std::string os = read_key("/etc/os-release", "PRETTY_NAME", '=');
  utsname u{};
  if (uname(&u) == 0)
    os += fmt::format("{}{} {} {}", os.empty() ? "" : ", ", u.sysname, u.release, u.machine);
  std::string flags = trim(KAIROS_BENCH_CXX_FLAGS);
#ifdef NDEBUG
  const char* asserts = "asserts off";
#else
  const char* asserts = "asserts on";
#endif
  return {
      fmt::format("Machine: {}; {} logical CPUs ({} usable by this process); caches {}", cpu,
                  logical, std::thread::hardware_concurrency(), cache_text()),
      fmt::format("OS: {}", os.empty() ? "unknown" : os),
      fmt::format("Compiler: {}; CMake build type {} ({}; {})", compiler_text(),
                  KAIROS_BENCH_BUILD_TYPE, flags.empty() ? "no extra flags" : flags, asserts),
  };
}

// ---------------------------------------------------------------------------------------------
// Output

enum class Format { kMarkdown, kTsv };

std::string sizes_text(double ratio) {
  return ratio > 1.0 ? fmt::format("1:{:g}", ratio) : std::string("mono");
}

std::string header(Format f) {
  if (f == Format::kTsv) {
    return "dim\tN\teta\tsizes\tstart\tqueue\teq_coll_per_particle\ttimed_coll_per_particle\t"
           "repeats\tcollisions_per_s\tevents_per_s\tcrossings_per_s\tstale_per_s\t"
           "other_per_s\tcrossings_per_coll\tstale_per_coll\tspread_pct\tbytes_per_particle\t"
           "timed_wall_s\teq_wall_s\tsetup_s\ttimed_collisions\ttimed_events\ttimed_crossings\t"
           "timed_stale\ttotal_collisions\ttotal_events\n";
  }
  return "| dim | N | η | sizes | start | queue | coll/particle eq + timed | collisions/s | "
         "events/s | crossings/s | stale/s | crossings/coll | stale/coll | spread | "
         "bytes/particle | timed s |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
}

std::string format_row(const Row& row, Format f) {
  const Run& b = row.best;
  const Counts& t = b.timed;
  const std::uint64_t other = t.events - t.collisions - t.crossings - t.stale;
  if (f == Format::kTsv) {
    return fmt::format(
        "{}\t{}\t{}\t{}\t{}\t{}\t{:g}\t{:g}\t{}\t{:.0f}\t{:.0f}\t{:.0f}\t{:.0f}\t{:.0f}\t{:.4f}\t"
        "{:.4f}\t{:.1f}\t{:.1f}\t{:.3f}\t{:.3f}\t{:.3f}\t{}\t{}\t{}\t{}\t{}\t{}\n",
        row.c.dimension, row.c.particles, row.c.eta, sizes_text(row.c.size_ratio), row.start,
        row.queue, row.c.equilibrate, row.c.timed, row.repeats, b.per_second(t.collisions),
        b.per_second(t.events), b.per_second(t.crossings), b.per_second(t.stale),
        b.per_second(other), b.per_collision(t.crossings), b.per_collision(t.stale),
        100.0 * row.spread, b.bytes_per_particle, b.wall, b.eq_wall, row.setup_seconds,
        t.collisions, t.events, t.crossings, t.stale, b.total.collisions, b.total.events);
  }
  const auto mega = [&](std::uint64_t n) { return fmt::format("{:.3f} M", b.per_second(n) / 1e6); };
  const std::string spread =
      row.repeats > 1 ? fmt::format("{:.0f} %", 100.0 * row.spread) : std::string("–");
  return fmt::format(
      "| {}D | {} | {:.2f} | {} | {} | {} | {:g} + {:g} | {} | {} | {} | {} | {:.3f} | {:.3f} | {} "
      "| {:.0f} | {:.2f} |\n",
      row.c.dimension, row.c.particles, row.c.eta, sizes_text(row.c.size_ratio), row.start,
      row.queue, row.c.equilibrate, row.c.timed, mega(t.collisions), mega(t.events),
      mega(t.crossings), mega(t.stale), b.per_collision(t.crossings), b.per_collision(t.stale),
      spread, b.bytes_per_particle, b.wall);
}

// Writes `text` to path.tmp, then renames it over `path`.
void write_atomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    out.flush();
    if (!out) throw std::runtime_error(fmt::format("cannot write {}", tmp));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error(fmt::format("cannot rename {} to {}", tmp, path));
  }
}

std::string quote_arg(const std::string& a) {
  if (!a.empty() && a.find_first_of(" \t\"'$\\") == std::string::npos) return a;
  std::string q = "'";
  for (char ch : a) q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return q + "'";
}

// ---------------------------------------------------------------------------------------------
// Options

struct Plan {
  std::vector<int> dims;
  std::vector<double> etas;
  std::vector<std::uint64_t> particles;
  std::vector<double> size_ratios;
  std::vector<std::string> queues;
  double equilibrate = 20, timed = 100;              // N <= large_from
  double equilibrate_large = 20, timed_large = 100;  // N > large_from
  std::uint64_t large_from = 32000;
  int repeat = 1;
};

Plan suite_plan(const std::string& suite) {
  Plan p;
  if (suite == "default") {  // the foundation cases
    p.dims = {3};
    p.etas = {0.45};
    p.particles = {32000, 1000000};
    p.size_ratios = {1.0};
    p.queues = {"calendar", "heap"};
  } else if (suite == "quick") {
    p.dims = {3, 2};
    p.etas = {0.1, 0.45};
    p.particles = {4000};
    p.size_ratios = {1.0, 1.4};
    p.queues = {"calendar", "heap"};
    p.equilibrate = p.equilibrate_large = 2;
    p.timed = p.timed_large = 10;
  } else if (suite == "full") {
    p.dims = {3, 2};
    p.etas = {0.1, 0.3, 0.45, 0.5};
    p.particles = {4000, 32000, 1000000};
    p.size_ratios = {1.0, 1.4};
    p.queues = {"calendar"};
    p.equilibrate_large = 10;
    p.timed_large = 20;
  } else {
    throw UsageError(fmt::format(
        "unknown --suite \"{}\"; use one of default, quick, full, granular, stepped, soft", suite));
  }
  return p;
}

double parse_size(const std::string& text) {
  const std::string s = trim(text);
  if (s == "mono") return 1.0;
  std::string number = s.rfind("1:", 0) == 0 ? s.substr(2) : s;
  std::size_t used = 0;
  double r = 0;
  try {
    r = std::stod(number, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != number.size() || number.empty() || !std::isfinite(r) || r < 1.0) {
    throw UsageError(fmt::format(
        "--sizes \"{}\" is invalid: use mono or a diameter ratio >= 1 (e.g. 1.4 or 1:1.4)", text));
  }
  return r;
}

void validate(const Plan& p) {
  for (int d : p.dims) {
    if (d != 2 && d != 3) throw UsageError(fmt::format("--dimension {} is invalid: use 2 or 3", d));
    const double max = d == 3 ? 0.74 : 0.9;
    for (double eta : p.etas) {
      if (!(eta > 0.0 && eta < max)) {
        throw UsageError(
            fmt::format("--eta {} is invalid in {}D: must be in (0, {})", eta, d, max));
      }
    }
  }
  for (std::uint64_t n : p.particles) {
    if (n < 2) throw UsageError(fmt::format("--particles {} is invalid: must be >= 2", n));
  }
  for (std::string_view q : p.queues) {
    EngineOptions unused;
    q = strip_variants(q, unused);
    if (q != "calendar" && q != "heap" && q != "tree") {
      throw UsageError(fmt::format("--queue \"{}\" is unknown; use calendar, heap or tree", q));
    }
  }
  if (p.queues.empty()) throw UsageError("--queue: give at least one queue");
  for (double x : {p.equilibrate, p.equilibrate_large}) {
    if (!(x >= 0.0 && std::isfinite(x))) {
      throw UsageError(fmt::format("--equilibrate {} is invalid: must be finite and >= 0", x));
    }
  }
  for (double x : {p.timed, p.timed_large}) {
    if (!(x > 0.0 && std::isfinite(x))) {
      throw UsageError(fmt::format("--timed {} is invalid: must be finite and > 0", x));
    }
  }
  if (p.repeat < 1) throw UsageError(fmt::format("--repeat {} is invalid: must be >= 1", p.repeat));
}

std::string lengths_text(const Plan& p) {
  const bool any_large = std::any_of(p.particles.begin(), p.particles.end(),
                                     [&](std::uint64_t n) { return n > p.large_from; });
  const bool any_small = std::any_of(p.particles.begin(), p.particles.end(),
                                     [&](std::uint64_t n) { return n <= p.large_from; });
  const bool differ = p.equilibrate != p.equilibrate_large || p.timed != p.timed_large;
  if (!differ || !any_large) {
    return fmt::format("equilibrate {:g}, then time {:g} collisions per particle", p.equilibrate,
                       p.timed);
  }
  std::string large = fmt::format(
      "equilibrate {:g}, then time {:g} collisions per particle at N > {} (shorter: "
      "run time)",
      p.equilibrate_large, p.timed_large, p.large_from);
  if (!any_small) return large;
  return fmt::format("equilibrate {:g}, then time {:g} collisions per particle at N <= {}; ",
                     p.equilibrate, p.timed, p.large_from) +
         large;
}

// The output document: printed as it grows, and rewritten to --output (if any) after every
// piece, so an interrupted run keeps what it measured.
class Output {
 public:
  explicit Output(std::string path) : path_(std::move(path)) {}
  void add(const std::string& text) {
    fmt::print("{}", text);
    std::fflush(stdout);
    doc_ += text;
    if (path_.empty()) return;
    if (!written_) {
      try {
        write_atomically(path_, doc_);
      } catch (const std::exception& e) {
        throw UsageError(fmt::format("--output {}: {}", path_, e.what()));
      }
      written_ = true;
    } else {
      write_atomically(path_, doc_);
    }
  }

 private:
  std::string path_, doc_;
  bool written_ = false;
};

// Date, command, machine and protocol: one line each, Markdown bullets or TSV comments.
std::string preamble(int argc, char** argv, const std::string& protocol, Format f) {
  std::string command = "kairos_bench";
  for (int i = 1; i < argc; ++i) command += " " + quote_arg(argv[i]);
  std::vector<std::string> facts;
#ifdef KAIROS_VERSION
  facts.push_back(fmt::format("Kairos {} benchmark, {}", KAIROS_VERSION, utc_now()));
#else
  facts.push_back(fmt::format("Kairos benchmark, {}", utc_now()));
#endif
  facts.push_back(fmt::format("Command: `{}`", command));
  for (auto& fact : machine_facts()) facts.push_back(fact);
  facts.push_back(protocol);
  std::string doc;
  for (const auto& fact : facts) doc += f == Format::kTsv ? "# " + fact + "\n" : "- " + fact + "\n";
  return doc;
}

std::string hard_sphere_protocol(const Plan& plan) {
  return fmt::format(
      "Protocol: {}; best of {} run(s) per case, queues interleaved; seed 1. Starts: "
      "monodisperse on the fcc (3D) / hex (2D) lattice; 50:50 mixtures by random insertion, or "
      "on that lattice with the species shuffled over the sites where random insertion is "
      "refused (too dense). Collisions per particle = 2 x collisions / N. Rates are over the "
      "timed part only; crossings and stale (invalidated) events are the other event types.",
      lengths_text(plan), plan.repeat);
}

void run_hard_spheres(const Plan& plan, Format fmt_kind, Output& out) {
  out.add(header(fmt_kind));
  for (std::uint64_t n : plan.particles) {
    for (int d : plan.dims) {
      for (double ratio : plan.size_ratios) {
        for (double eta : plan.etas) {
          const bool large = n > plan.large_from;
          const Case c{d,
                       n,
                       eta,
                       ratio,
                       large ? plan.equilibrate_large : plan.equilibrate,
                       large ? plan.timed_large : plan.timed};
          std::vector<Row> rows;
          try {
            rows = run_case(c, plan.queues, plan.repeat);
          } catch (const InputError& e) {
            throw InputError(fmt::format("{}D N={} eta={} sizes={}: {}", d, n, eta,
                                         sizes_text(ratio), e.what()));
          }
          std::string lines;
          for (const auto& row : rows) lines += format_row(row, fmt_kind);
          out.add(lines);
        }
      }
    }
  }
}

int run(int argc, char** argv) {
  CLI::App app{"Kairos benchmark driver (see bench/README.md)"};
  std::string suite = "default";
  std::vector<std::int64_t> particles;  // signed: "-5" is an error, not 2^64 - 5
  std::vector<double> etas, ratios;
  std::vector<int> dims;
  std::vector<std::string> queues, sizes, cases, scans, crossings, gathers, record_loads;
  std::vector<int> lj_steps;
  std::vector<double> contact_ratios;
  std::int64_t dem_steps = 0;
  std::string table_cache;
  std::string lammps_dir;
  double eq = 0, timed = 0;
  int repeat = 1;
  std::string format = "markdown", output;
  auto* o_suite = app.add_option(
      "--suite", suite,
      "case set: default (3D, eta 0.45, N 32000 and 1000000, calendar and heap, "
      "20 + 100 collisions per particle); quick (smoke test, a few seconds: 3D and "
      "2D, eta 0.1 and 0.45, N 4000, mono and 1.4, both queues, 2 + 10); full (3D "
      "and 2D, eta 0.1 0.3 0.45 0.5, N 4000 32000 1000000, mono and 1.4, calendar, "
      "20 + 100, but 10 + 20 at N > 32000); granular (--case gas,bed,pile: an inelastic gas "
      "and a vibrated bed against the elastic fluid, a pile settling with sleeping particles); "
      "stepped (--case sw,lj: the square-well fluid and stepped Lennard-Jones tables against "
      "hard spheres); soft (--case dashpot,hertz: a dilute soft-sphere gas, event-driven with "
      "the Müller–Pöschel map against Kairos's DEM and hard spheres). The options below "
      "override its parts");
  auto* o_case = app.add_option("--case", cases,
                                "granular cases: gas, bed, pile (imply --suite granular); "
                                "stepped cases: sw, lj (imply --suite stepped); soft cases: "
                                "dashpot, hertz (imply --suite soft)")
                     ->delimiter(',');
  auto* o_steps =
      app.add_option("--steps", lj_steps,
                     "stepped suite: attractive steps of the Lennard-Jones tables (default "
                     "5,10,20,40)")
          ->delimiter(',');
  auto* o_scan = app.add_option("--scan", scans,
                                "stepped suite: candidate loops, run interleaved: vector "
                                "(AVX-512 where available, the default) and/or scalar")
                     ->delimiter(',');
  auto* o_crossings =
      app.add_option("--crossings", crossings,
                     "cell crossings: incremental (the default: a crossing scans only the cells "
                     "new to the neighbourhood) and/or full (every crossing rescans all "
                     "neighbours, as before); run interleaved with the queues (default, quick "
                     "and full suites; the soft and granular suites take one)")
          ->delimiter(',');
  auto* o_gathers =
      app.add_option("--list-gather", gathers,
                     "how cell lists are walked: auto (the default: AVX-512 gathers on Intel, "
                     "one by one elsewhere), scalar and/or vector (AVX-512 gathers); run "
                     "interleaved with the queues (default, quick and full suites)")
          ->delimiter(',');
  auto* o_record_loads =
      app.add_option("--record-loads", record_loads,
                     "how the AVX-512 loops read candidates' records: auto (the default: "
                     "gathers on Intel, row loads elsewhere), gather and/or rows (one load per "
                     "record and a transpose); run interleaved with the queues (default, quick "
                     "and full suites)")
          ->delimiter(',');
  auto* o_ratios = app.add_option("--contact-ratio", contact_ratios,
                                  "soft suite: mean free time / contact time (default 100,1000)")
                       ->delimiter(',');
  auto* o_dem_steps =
      app.add_option("--dem-steps", dem_steps, "soft suite: DEM timed steps per sample (2000)");
  auto* o_table_cache = app.add_option(
      "--table-cache", table_cache,
      "soft suite: lookup-table cache directory (default: a fresh temporary one, removed after)");
  auto* o_lammps = app.add_option(
      "--lammps-dir", lammps_dir,
      "soft suite: also write every case for LAMMPS into this directory (start state, input, "
      "Kairos's figures in cases.tsv; bench/lammps_soft.sh runs them)");
  auto* o_particles = app.add_option("--particles", particles, "particle numbers")->delimiter(',');
  auto* o_eta =
      app.add_option("--eta", etas, "packing fractions (area fractions in 2D)")->delimiter(',');
  auto* o_dim = app.add_option("--dimension", dims, "dimensions, 2 and/or 3")->delimiter(',');
  auto* o_queue =
      app.add_option("--queue", queues, "event queues (calendar, heap, tree), run interleaved")
          ->delimiter(',');
  auto* o_sizes = app.add_option("--sizes", sizes,
                                 "size distributions: mono and/or the diameter ratio of a 50:50 "
                                 "mixture, e.g. --sizes mono,1.4")
                      ->delimiter(',');
  auto* o_ratio = app.add_option("--size-ratio", ratios,
                                 "diameter ratios of 50:50 mixtures (1 = monodisperse); "
                                 "same as --sizes")
                      ->delimiter(',');
  auto* o_eq = app.add_option("--equilibrate", eq, "untimed collisions per particle first (all N)");
  auto* o_timed = app.add_option("--timed", timed, "timed collisions per particle (all N)");
  auto* o_repeat =
      app.add_option("--repeat", repeat, "repetitions per case (best reported, spread shown)");
  app.add_option("--format", format, "markdown (default) or tsv");
  app.add_option("--output", output, "also write the output to this file (atomically)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    throw UsageError(e.what());
  }

  Format fmt_kind = Format::kMarkdown;
  if (format == "tsv") {
    fmt_kind = Format::kTsv;
  } else if (format != "markdown" && format != "md") {
    throw UsageError(fmt::format("--format \"{}\" is unknown; use markdown or tsv", format));
  }

  if (o_case->count() > 0 && o_suite->count() == 0) {
    const bool stepped_cases = std::all_of(
        cases.begin(), cases.end(), [](const std::string& c) { return c == "sw" || c == "lj"; });
    const bool soft_cases = std::all_of(cases.begin(), cases.end(), [](const std::string& c) {
      return c == "dashpot" || c == "hertz";
    });
    suite = stepped_cases ? "stepped" : soft_cases ? "soft" : "granular";
  }
  if (suite != "soft" && (o_ratios->count() > 0 || o_dem_steps->count() > 0 ||
                          o_table_cache->count() > 0 || o_lammps->count() > 0))
    throw UsageError(
        "--contact-ratio, --dem-steps, --table-cache and --lammps-dir need --suite soft");
  for (const std::string& c : crossings) {
    if (c != "incremental" && c != "full")
      throw UsageError(fmt::format("--crossings \"{}\" is unknown; use incremental or full", c));
  }
  if (o_crossings->count() > 0 && suite == "stepped")
    throw UsageError("--crossings does not apply to the stepped suite (steps keep full scans)");
  if ((suite == "soft" || suite == "granular") && crossings.size() > 1)
    throw UsageError("--suite " + suite + " takes one --crossings");
  for (const std::string& g : gathers) {
    if (g != "auto" && g != "scalar" && g != "vector")
      throw UsageError(
          fmt::format("--list-gather \"{}\" is unknown; use auto, scalar or vector", g));
    if (g == "vector" && !cpu_has_avx512())
      throw UsageError("--list-gather vector needs a CPU with AVX-512");
  }
  if (o_gathers->count() > 0 && suite != "default" && suite != "quick" && suite != "full")
    throw UsageError("--list-gather needs the default, quick or full suite");
  for (const std::string& r : record_loads) {
    if (r != "auto" && r != "gather" && r != "rows")
      throw UsageError(
          fmt::format("--record-loads \"{}\" is unknown; use auto, gather or rows", r));
    if (r != "auto" && !cpu_has_avx512())
      throw UsageError("--record-loads gather and rows need a CPU with AVX-512");
  }
  if (o_record_loads->count() > 0 && suite != "default" && suite != "quick" && suite != "full")
    throw UsageError("--record-loads needs the default, quick or full suite");
  if (suite == "soft") {
    if (o_queue->count() > 0 || o_sizes->count() > 0 || o_ratio->count() > 0 ||
        o_dim->count() > 0 || fmt_kind == Format::kTsv) {
      throw UsageError("--suite soft takes no --queue, --sizes, --dimension or --format tsv");
    }
    if (particles.size() > 1) throw UsageError("--suite soft takes one --particles");
    bench::SoftPlan sp;
    if (o_case->count() > 0) sp.cases = cases;
    if (!particles.empty()) {
      if (particles[0] < 1) throw UsageError("--particles must be positive");
      sp.particles = static_cast<std::uint64_t>(particles[0]);
    }
    if (o_eta->count() > 0) sp.etas = etas;
    if (o_ratios->count() > 0) sp.contact_ratios = contact_ratios;
    if (o_dem_steps->count() > 0) {
      if (dem_steps < 1) throw UsageError("--dem-steps must be positive");
      sp.dem_steps = static_cast<long>(dem_steps);
    }
    sp.table_cache = table_cache;
    sp.lammps_dir = lammps_dir;
    sp.full_crossing_scans = !crossings.empty() && crossings[0] == "full";
    if (o_eq->count() > 0) sp.equilibrate = eq;
    if (o_timed->count() > 0) sp.timed = timed;
    if (o_repeat->count() > 0) sp.repeat = repeat;
    try {
      bench::validate(sp);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
    Output out(output);
    out.add(preamble(argc, argv, bench::soft_protocol(sp), fmt_kind));
    bench::run_soft(sp, [&](const std::string& text) { out.add(text); });
    return 0;
  }
  if (suite != "stepped" && (o_steps->count() > 0 || o_scan->count() > 0))
    throw UsageError("--steps and --scan need --suite stepped");
  if (suite == "stepped") {
    if (o_queue->count() > 0 || o_sizes->count() > 0 || o_ratio->count() > 0 ||
        o_eta->count() > 0 || o_dim->count() > 0 || fmt_kind == Format::kTsv) {
      throw UsageError(
          "--suite stepped takes no --queue, --sizes, --eta, --dimension or --format tsv");
    }
    if (particles.size() > 1) throw UsageError("--suite stepped takes one --particles");
    bench::SteppedPlan sp;
    if (o_case->count() > 0) sp.cases = cases;
    if (o_steps->count() > 0) sp.lj_steps = lj_steps;
    if (o_scan->count() > 0) sp.scans = scans;
    if (!particles.empty()) {
      if (particles[0] < 1) throw UsageError("--particles must be positive");
      sp.particles = static_cast<std::uint64_t>(particles[0]);
    }
    if (o_eq->count() > 0) sp.equilibrate = eq;
    if (o_timed->count() > 0) sp.timed = timed;
    if (o_repeat->count() > 0) sp.repeat = repeat;
    try {
      bench::validate(sp);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
    Output out(output);
    out.add(preamble(argc, argv, bench::stepped_protocol(sp), fmt_kind));
    bench::run_stepped(sp, [&](const std::string& text) { out.add(text); });
    return 0;
  }
  if (suite == "granular") {
    if (o_queue->count() > 0 || o_sizes->count() > 0 || o_ratio->count() > 0 ||
        fmt_kind == Format::kTsv) {
      throw UsageError("--suite granular takes no --queue, --sizes or --format tsv");
    }
    if (particles.size() > 1 || etas.size() > 1) {
      throw UsageError("--suite granular takes one --particles and one --eta");
    }
    bench::GranularPlan g;
    if (o_case->count() > 0) g.cases = cases;
    g.dims = dims;
    if (!particles.empty()) {
      if (particles[0] < 1) throw UsageError("--particles must be positive");
      g.particles = static_cast<std::uint64_t>(particles[0]);
    }
    if (!etas.empty()) g.eta = etas[0];
    if (o_eq->count() > 0) g.equilibrate = eq;
    if (o_timed->count() > 0) g.timed = timed;
    if (o_repeat->count() > 0) g.repeat = repeat;
    g.full_crossing_scans = !crossings.empty() && crossings[0] == "full";
    try {
      bench::validate(g);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
    Output out(output);
    out.add(preamble(argc, argv, bench::granular_protocol(g), fmt_kind));
    bench::run_granular(g, [&](const std::string& text) { out.add(text); });
    return 0;
  }
  if (o_case->count() > 0) throw UsageError("--case needs --suite granular, stepped or soft");

  Plan plan = suite_plan(suite);
  if (o_particles->count() > 0) {
    plan.particles.clear();
    for (std::int64_t n : particles) {
      if (n < 2) throw UsageError(fmt::format("--particles {} is invalid: must be >= 2", n));
      plan.particles.push_back(static_cast<std::uint64_t>(n));
    }
  }
  if (o_eta->count() > 0) plan.etas = etas;
  if (o_dim->count() > 0) plan.dims = dims;
  if (o_queue->count() > 0) plan.queues = queues;
  if (o_crossings->count() > 0)
    plan.queues = with_variants(plan.queues, crossings, {{"full", kFullScans}});
  if (o_gathers->count() > 0) {
    plan.queues =
        with_variants(plan.queues, gathers, {{"scalar", kScalarWalk}, {"vector", kVectorGather}});
  }
  if (o_record_loads->count() > 0) {
    plan.queues =
        with_variants(plan.queues, record_loads, {{"gather", kGatherLoads}, {"rows", kRowLoads}});
  }
  if (o_sizes->count() > 0 || o_ratio->count() > 0) {
    plan.size_ratios.clear();
    for (const auto& s : sizes) plan.size_ratios.push_back(parse_size(s));
    for (double r : ratios) plan.size_ratios.push_back(parse_size(fmt::format("{}", r)));
  }
  if (o_eq->count() > 0) plan.equilibrate = plan.equilibrate_large = eq;
  if (o_timed->count() > 0) plan.timed = plan.timed_large = timed;
  if (o_repeat->count() > 0) plan.repeat = repeat;
  validate(plan);

  Output out(output);
  out.add(preamble(argc, argv, hard_sphere_protocol(plan), fmt_kind) +
          (fmt_kind == Format::kTsv ? "" : "\n"));
  run_hard_spheres(plan, fmt_kind, out);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "kairos_bench: error: %s (see --help)\n", e.what());
    return 2;
  } catch (const InputError& e) {
    std::fprintf(stderr, "kairos_bench: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kairos_bench: error: %s\n", e.what());
    return 1;
  }
}

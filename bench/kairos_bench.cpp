// Benchmark driver: hard-sphere / hard-disk fluids started on a lattice, equilibrated, then
// timed over a fixed number of collisions per particle. Prints one Markdown table row per case.
//
//   kairos_bench                          # the foundation suite (bench/README.md)
//   kairos_bench --particles 32000 --eta 0.45 --queue calendar,heap --repeat 3
//
// Cases given several queues are run interleaved (A B A B ...) so that machine noise hits
// every variant alike; the best of the repeats is reported with the spread.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "engine/event_engine.hpp"
#include "init/initial_state.hpp"
#include "scheduler/binary_heap_queue.hpp"
#include "scheduler/calendar_queue.hpp"

namespace {

using namespace kairos;

struct Case {
  int dimension = 3;
  std::uint64_t particles = 32000;
  double eta = 0.45;
  std::string lattice;      // default: fcc / hex
  double size_ratio = 1.0;  // > 1: 50:50 bidisperse mixture (random insertion)
};

struct Result {
  double collisions_per_second = 0, events_per_second = 0;
  double crossings_per_collision = 0, stale_per_collision = 0;
  std::size_t bytes_per_particle = 0;
};

template <int D>
ParticleSystem<D> make_system(const Case& c, std::uint64_t seed) {
  SystemConfig sys;
  sys.dimension = D;
  sys.particles = c.particles;
  sys.packing_fraction = c.eta;
  sys.lattice = c.lattice.empty() ? (D == 3 ? "fcc" : "hex") : c.lattice;
  sys.seed = seed;
  if (c.size_ratio > 1.0) {
    sys.lattice = "random";
    sys.species = {{"A", 1.0, 1.0, 0.5}, {"B", c.size_ratio, 1.0, 0.5}};
  }
  std::mt19937_64 rng(seed);
  return to_particle_system<D>(make_initial_state<D>(sys, rng));
}

template <int D, class Queue>
Result measure(const ParticleSystem<D>& start, double equilibrate, double timed) {
  EventEngine<D, Queue> engine(start);
  const auto n = static_cast<double>(engine.size());
  const auto eq_target = static_cast<std::uint64_t>(equilibrate * n / 2.0);
  while (engine.counters().collisions < eq_target) engine.step();
  const EventCounters c0 = engine.counters();
  const auto target = c0.collisions + static_cast<std::uint64_t>(timed * n / 2.0);
  const auto t0 = std::chrono::steady_clock::now();
  while (engine.counters().collisions < target) engine.step();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const EventCounters& c = engine.counters();
  const auto dc = static_cast<double>(c.collisions - c0.collisions);
  Result r;
  r.collisions_per_second = dc / wall;
  r.events_per_second = static_cast<double>(c.events - c0.events) / wall;
  r.crossings_per_collision = static_cast<double>(c.cell_crossings - c0.cell_crossings) / dc;
  r.stale_per_collision = static_cast<double>(c.stale_events - c0.stale_events) / dc;
  r.bytes_per_particle = engine.bytes_per_particle();
  return r;
}

template <int D>
Result measure_queue(const std::string& queue, const ParticleSystem<D>& s, double eq,
                     double timed) {
  if (queue == "heap") return measure<D, BinaryHeapQueue>(s, eq, timed);
  return measure<D, CalendarQueue>(s, eq, timed);
}

void run_case(const Case& c, const std::vector<std::string>& queues, int repeat, double eq,
              double timed) {
  std::vector<std::vector<Result>> results(queues.size());
  for (int r = 0; r < repeat; ++r) {
    for (std::size_t q = 0; q < queues.size(); ++q) {
      if (c.dimension == 2) {
        results[q].push_back(measure_queue<2>(queues[q], make_system<2>(c, 1), eq, timed));
      } else {
        results[q].push_back(measure_queue<3>(queues[q], make_system<3>(c, 1), eq, timed));
      }
    }
  }
  for (std::size_t q = 0; q < queues.size(); ++q) {
    auto& rs = results[q];
    std::sort(rs.begin(), rs.end(), [](const Result& a, const Result& b) {
      return a.collisions_per_second > b.collisions_per_second;
    });
    const Result& best = rs.front();
    const double worst = rs.back().collisions_per_second;
    fmt::print(
        "| {}D | {} | {:.2f} | {} | {} | {:.3f} M | {:.3f} M | {:.0f} % | {:.3f} | {:.3f} | {} |\n",
        c.dimension, c.particles, c.eta,
        c.size_ratio > 1 ? fmt::format("1:{}", c.size_ratio) : "mono", queues[q],
        best.collisions_per_second / 1e6, best.events_per_second / 1e6,
        100.0 * (best.collisions_per_second - worst) / best.collisions_per_second,
        best.crossings_per_collision, best.stale_per_collision, best.bytes_per_particle);
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Kairos benchmark driver (see bench/README.md)"};
  std::vector<std::uint64_t> particles;
  std::vector<double> etas;
  std::vector<int> dims;
  std::vector<std::string> queues{"calendar", "heap"};
  double ratio = 1.0, eq = 20.0, timed = 100.0;
  int repeat = 1;
  app.add_option("--particles", particles, "particle numbers (default 32000 and 1000000)");
  app.add_option("--eta", etas, "packing fractions (default 0.45)");
  app.add_option("--dimension", dims, "dimensions (default 3)");
  app.add_option("--queue", queues, "event queues to compare, run interleaved")->delimiter(',');
  app.add_option("--size-ratio", ratio, "diameter ratio of a 50:50 mixture (1 = monodisperse)");
  app.add_option("--equilibrate", eq, "untimed collisions per particle first");
  app.add_option("--timed", timed, "timed collisions per particle");
  app.add_option("--repeat", repeat, "repetitions per case (best reported, spread shown)");
  CLI11_PARSE(app, argc, argv);
  if (particles.empty()) particles = {32000, 1000000};
  if (etas.empty()) etas = {0.45};
  if (dims.empty()) dims = {3};

  fmt::print(
      "| dim | N | eta | sizes | queue | collisions/s | events/s | spread | crossings/coll | "
      "stale/coll | bytes/particle |\n");
  fmt::print("|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int d : dims)
    for (double eta : etas)
      for (std::uint64_t n : particles) run_case({d, n, eta, "", ratio}, queues, repeat, eq, timed);
  return 0;
}

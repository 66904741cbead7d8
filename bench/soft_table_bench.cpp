// Soft-sphere collision map tables (src/interactions/soft_map_table.hpp): build time, size and
// accuracy of the default-tolerance tables of a dashpot and a viscoelastic Hertz contact, and
// the cost of one lookup against one direct integration (collision_map), for collisions with
// normal speeds log-uniform over the table's range and random impact parameters (v_t/v_n =
// tan of the incidence angle, sin^2 uniform: what a gas's random collisions give). Lookup and
// direct costs are CPU time of one thread; the build's wall and CPU time (all threads).
//
//   soft_table_bench [tolerance=1e-6] [threads=0 (all)] [min_speed=0.01] [max_speed=10]
#include <time.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "interactions/soft_map_table.hpp"

namespace {

using namespace kairos;

// CPU time of this thread (or of the process, all threads): on a shared machine it excludes
// the time the scheduler gives to other jobs.
double cpu_seconds(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void run(const char* name, const SoftTableSpec& spec, int threads) {
  SoftTableBuildOptions options;
  options.threads = threads;
  const double build_cpu0 = cpu_seconds(CLOCK_PROCESS_CPUTIME_ID);
  const SoftMapTable table = SoftMapTable::build(spec, options);
  const double build_cpu = cpu_seconds(CLOCK_PROCESS_CPUTIME_ID) - build_cpu0;
  const SoftTableReport& r = table.report();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<CollisionUnits> collisions;
  const std::size_t n = 1 << 16;
  while (collisions.size() < n) {
    const double v_n =
        spec.min_normal_speed * std::pow(spec.max_normal_speed / spec.min_normal_speed, unit(rng));
    const double s2 = unit(rng);  // sin^2 of the incidence angle
    const double ratio = std::sqrt(s2 / (1.0 - s2));
    if (!(ratio <= spec.max_tangential_ratio)) continue;
    collisions.push_back(
        reduce_collision(spec.law, spec.reduced_mass, spec.contact_distance, v_n, ratio * v_n));
  }
  // Lookups: every collision, many rounds.
  double sink = 0.0;
  long found = 0;
  const int rounds = 40;
  double c0 = cpu_seconds(CLOCK_THREAD_CPUTIME_ID);
  for (int k = 0; k < rounds; ++k) {
    for (const CollisionUnits& u : collisions) {
      CollisionMap m;
      if (table.lookup(u, m)) {
        ++found;
        sink += m.eps_t + m.eps_r + m.eps_phi;
      }
    }
  }
  const double lookup_ns =
      (cpu_seconds(CLOCK_THREAD_CPUTIME_ID) - c0) / (rounds * static_cast<double>(n)) * 1e9;
  // Direct integrations: a subset.
  const std::size_t n_direct = 2000;
  c0 = cpu_seconds(CLOCK_THREAD_CPUTIME_ID);
  for (std::size_t k = 0; k < n_direct; ++k) sink += collision_map(collisions[k].reduced).eps_t;
  const double direct_us =
      (cpu_seconds(CLOCK_THREAD_CPUTIME_ID) - c0) / static_cast<double>(n_direct) * 1e6;
  // Whole-table errors at fresh random collisions (not the build's check points).
  double err[4] = {};
  for (std::size_t k = 0; k < n_direct; ++k) {
    CollisionMap m;
    if (!table.lookup(collisions[k], m)) continue;
    const CollisionMap d = collision_map(collisions[k].reduced);
    const double e[4] = {m.eps_t / d.eps_t - 1.0, m.eps_rdot / d.eps_rdot - 1.0,
                         m.eps_phi / d.eps_phi - 1.0,
                         d.end_overlap == 0.0 ? 0.0 : m.end_overlap / d.end_overlap - 1.0};
    for (int c = 0; c < 4; ++c) err[c] = std::max(err[c], std::abs(e[c]));
  }
  const double nodes = static_cast<double>(table.grid().nu) * table.grid().nw;
  std::printf(
      "| %s | %d x %d | %.0f KiB | %.2f s (%.2f s CPU) | %d | %.1e %.1e %.1e %.1e | %.1e %.1e %.1e "
      "%.1e | "
      "%.0f ns | %.1f us | %.0fx | %.1e |\n",
      name, table.grid().nu, table.grid().nw, nodes * 24.0 / 1024.0, r.build_seconds, build_cpu,
      r.refinements, r.max_error[0], r.max_error[1], r.max_error[2], r.max_error[3], err[0], err[1],
      err[2], err[3], lookup_ns, direct_us, direct_us * 1e3 / lookup_ns, r.below_min_ratio_error);
  if (found != rounds * static_cast<long>(n))
    std::printf("  (%ld lookups fell outside)\n", rounds * static_cast<long>(n) - found);
  if (sink == 0.123) std::printf(" ");
}

}  // namespace

int main(int argc, char** argv) {
  const double tolerance = argc > 1 ? std::atof(argv[1]) : 1e-6;
  const int threads = argc > 2 ? std::atoi(argv[2]) : 0;
  const double v_min = argc > 3 ? std::atof(argv[3]) : 0.01;
  const double v_max = argc > 4 ? std::atof(argv[4]) : 10.0;
  // mu = 0.5, l = 1 (two unit spheres of mass 1). Dashpot k = 1e5 with e = 0.74 (c_dis = 0.2);
  // Hertz rho = 1e5 with A such that c_dis = 0.1 at v_n = 1 (e = 0.85 there).
  SoftTableSpec dashpot;
  dashpot.law = SoftContactLaw::linear_dashpot(1e5, 0.2 * std::sqrt(1e5 * 0.5));
  SoftTableSpec hertz;
  hertz.law = SoftContactLaw::viscoelastic_hertz(1e5, 0.1 * std::pow(0.25 / 1e10, 0.2));
  for (SoftTableSpec* s : {&dashpot, &hertz}) {
    s->reduced_mass = 0.5;
    s->contact_distance = 1.0;
    s->min_normal_speed = v_min;
    s->max_normal_speed = v_max;
    s->tolerance = tolerance;
  }
  std::printf("speeds %g..%g, v_t/v_n up to %g, tolerance %g\n\n", v_min, v_max,
              dashpot.max_tangential_ratio, tolerance);
  std::printf(
      "| contact | nodes (u x w) | size | build | refinements | build check max errors "
      "(eps_t, eps_rdot, eps_phi, end_overlap) | fresh sample errors | lookup | direct | "
      "ratio | below 1e-4 |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
  run("dashpot c_dis 0.2", dashpot, threads);
  run("Hertz c_dis 0.1 at v=1", hertz, threads);
  return 0;
}

#include "init/initial_state.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/memory_budget.hpp"
#include "core/periodic.hpp"
#include "core/setup_progress.hpp"
#include "core/stop_flag.hpp"
#include "init/insertion_grid.hpp"
#include "io/config_choices.hpp"

namespace kairos {
namespace {

// ---------------------------------------------------------------------------------------------
// Platform-independent random numbers (the standard distributions are implementation-defined).

// Uniform in [0, 1) with 53 random bits.
// Loops over all particles of the setup poll the stop flag every so many iterations (a few
// milliseconds of work): SIGINT and run.max_wall_seconds end the setup of 10^7 particles too.
inline void poll_stop(std::uint64_t i) {
  if ((i & 0xffffu) == 0xffffu) throw_if_stop_requested();
}

double uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

// Uniform integer in [0, n), n >= 1, without modulo bias.
std::uint64_t uniform_below(std::mt19937_64& rng, std::uint64_t n) {
  const std::uint64_t max = std::numeric_limits<std::uint64_t>::max();
  const std::uint64_t limit = max - (max % n + 1) % n;  // accept [0, limit]: a multiple of n
  std::uint64_t r = rng();
  while (r > limit) r = rng();
  return r % n;
}

template <class T>
void shuffle(std::vector<T>& v, std::mt19937_64& rng) {
  for (std::size_t i = v.size(); i > 1; --i) {
    const std::size_t j = uniform_below(rng, i);
    std::swap(v[i - 1], v[j]);
  }
}

// Standard normal deviates by Box-Muller; the second deviate of each pair is kept for the next
// call.
class NormalSource {
 public:
  double operator()(std::mt19937_64& rng) {
    if (has_cached_) {
      has_cached_ = false;
      return cached_;
    }
    const double u1 = 1.0 - uniform01(rng);  // (0, 1]
    const double u2 = uniform01(rng);
    const double r = std::sqrt(-2.0 * std::log(u1));
    const double theta = 2.0 * std::numbers::pi * u2;
    cached_ = r * std::sin(theta);
    has_cached_ = true;
    return r * std::cos(theta);
  }

 private:
  double cached_ = 0.0;
  bool has_cached_ = false;
};

// Neumaier's compensated summation: momentum and kinetic energy of many particles accurate to
// the round-off of the result rather than of the partial sums.
class CompensatedSum {
 public:
  void add(double x) {
    const double t = sum_ + x;
    if (std::abs(sum_) >= std::abs(x)) {
      correction_ += (sum_ - t) + x;
    } else {
      correction_ += (x - t) + sum_;
    }
    sum_ = t;
  }
  double value() const { return sum_ + correction_; }

 private:
  double sum_ = 0.0;
  double correction_ = 0.0;
};

// ---------------------------------------------------------------------------------------------
// Geometry helpers.

// Rounds x > 0 down to 6 significant digits, so that the printed value is itself allowed.
double round_down_6(double x) {
  if (!(x > 0.0) || !std::isfinite(x)) return x;
  const double scale = std::pow(10.0, std::floor(std::log10(x)) - 5.0);
  const double r = std::floor(x / scale) * scale;
  return r > x ? std::nextafter(x, 0.0) : r;
}

// ---------------------------------------------------------------------------------------------
// Lattices.

struct LatticeSpec {
  std::string_view name;
  int dimension;
  std::uint64_t sites_per_cell;
  std::array<std::array<double, 3>, 4> basis;  // fractional coordinates within the cell
  std::array<double, 3> cell_shape;            // cell edges in units of the lattice constant
  double nearest_neighbour;                    // in units of the lattice constant
  double close_packed;                         // packing fraction at contact, full lattice
};

constexpr double kPi = std::numbers::pi;
constexpr double kSqrt2 = std::numbers::sqrt2;
constexpr double kSqrt3 = std::numbers::sqrt3;
// clang-format off
constexpr LatticeSpec kLattices[] = {
    {"fcc", 3, 4, {{{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}}}, {1, 1, 1},
     kSqrt2 / 2, kPi / (3 * kSqrt2)},
    {"bcc", 3, 2, {{{0, 0, 0}, {0.5, 0.5, 0.5}}}, {1, 1, 1}, kSqrt3 / 2, kSqrt3 * kPi / 8},
    {"sc", 3, 1, {{{0, 0, 0}}}, {1, 1, 1}, 1.0, kPi / 6},
    {"square", 2, 1, {{{0, 0, 0}}}, {1, 1, 1}, 1.0, kPi / 4},
    // triangular: rectangular cells a x a sqrt(3) holding two sites
    {"hex", 2, 2, {{{0, 0, 0}, {0.5, 0.5, 0}}}, {1, kSqrt3, 1}, 1.0, kPi / (2 * kSqrt3)},
};
// clang-format on

// Random sequential insertion jams near 0.38 (3D) / 0.547 (2D); beyond these it is refused.
constexpr double kRandomMaxPacking3 = 0.35;
constexpr double kRandomMaxPacking2 = 0.50;
}  // namespace

double random_insertion_limit(int dimension) {
  return dimension == 3 ? kRandomMaxPacking3 : kRandomMaxPacking2;
}

namespace {
constexpr std::uint64_t kMaxInsertionAttempts = 1'000'000;  // per particle

// "fcc, bcc, sc" / "square, hex", plus ", random" when asked.
std::string lattice_list(int dimension, bool with_random) {
  std::string s;
  for (const auto& l : kLattices) {
    if (l.dimension != dimension) continue;
    if (!s.empty()) s += ", ";
    s += l.name;
  }
  return with_random ? s + ", random" : s;
}

// Smallest n with m n^3 >= N (D = 3) or m n^2 >= N (D = 2).
std::uint64_t cells_per_axis(std::uint64_t N, std::uint64_t m, int D) {
  const auto enough = [&](std::uint64_t n) {
    std::uint64_t sites = m;
    for (int k = 0; k < D; ++k) sites *= n;
    return sites >= N;
  };
  const double cells = std::ceil(static_cast<double>(N) / static_cast<double>(m));
  auto n = static_cast<std::uint64_t>(std::pow(cells, 1.0 / D));
  n = std::max<std::uint64_t>(n, 1);
  while (!enough(n)) ++n;
  while (n > 1 && enough(n - 1)) --n;
  return n;
}

// Triangular lattice in rectangular cells a x a sqrt(3): for each ny the fewest columns
// nx = ceil(N / (2 ny)); among these the box closest to square (aspect sqrt(3) ny / nx nearest
// 1 in log), ties to fewer sites. The aspect grows strictly with ny, so only the two ny around
// aspect 1 compete. All comparisons are exact integer arithmetic.
std::array<std::uint64_t, 2> hex_cells(std::uint64_t N) {
  const auto nx_of = [N](std::uint64_t ny) { return (N + 2 * ny - 1) / (2 * ny); };
  const auto not_tall = [&](std::uint64_t ny) {  // sqrt(3) ny <= nx
    const std::uint64_t nx = nx_of(ny);
    return 3 * ny * ny <= nx * nx;
  };
  if (!not_tall(1)) return {nx_of(1), 1};
  std::uint64_t lo = 1;  // not_tall(lo)
  std::uint64_t hi = static_cast<std::uint64_t>(std::sqrt(static_cast<double>(N))) + 2;
  while (not_tall(hi)) hi *= 2;
  while (hi - lo > 1) {  // not_tall(lo), !not_tall(hi)
    const std::uint64_t mid = lo + (hi - lo) / 2;
    (not_tall(mid) ? lo : hi) = mid;
  }
  const std::uint64_t ax = nx_of(lo), bx = nx_of(hi);
  // |ln aspect_a| vs |ln aspect_b| with aspect_a <= 1 < aspect_b: a is closer when
  // aspect_a * aspect_b > 1, i.e. 3 ny_a ny_b > nx_a nx_b.
  const std::uint64_t lhs = 3 * lo * hi, rhs = ax * bx;
  if (lhs > rhs) return {ax, lo};
  if (lhs < rhs) return {bx, hi};
  return ax * lo <= bx * hi ? std::array<std::uint64_t, 2>{ax, lo}
                            : std::array<std::uint64_t, 2>{bx, hi};
}

// Everything about the box that follows from (N, packing fraction, species, lattice) alone.
template <int D>
struct Layout {
  std::vector<std::uint64_t> counts;  // per species
  double solid_volume = 0.0;          // sum of the particle volumes
  std::array<double, D> box{};
  const LatticeSpec* lattice = nullptr;  // nullptr: random insertion
  std::array<std::uint64_t, D> cells{};
  std::uint64_t sites = 0;
  double lattice_constant = 0.0;
  double nearest_neighbour = 0.0;
};

template <int D>
Layout<D> make_layout(const std::vector<SpeciesConfig>& species, std::uint64_t N, double eta,
                      const LatticeSpec* lattice, double solid_volume = 0.0) {
  Layout<D> out;
  std::vector<double> fractions;
  for (const auto& s : species) fractions.push_back(s.fraction);
  out.counts = largest_remainder_counts(fractions, N);
  for (std::size_t s = 0; s < species.size(); ++s) {
    out.solid_volume +=
        static_cast<double>(out.counts[s]) * particle_volume<D>(species[s].diameter);
  }
  if (solid_volume > 0.0) out.solid_volume = solid_volume;  // drawn diameters
  const double volume = out.solid_volume / eta;
  out.lattice = lattice;
  if (lattice == nullptr) {
    const double L = D == 3 ? std::cbrt(volume) : std::sqrt(volume);
    out.box.fill(L);
    return out;
  }
  if (lattice->name == "hex") {
    const auto c = hex_cells(N);
    out.cells[0] = c[0];
    out.cells[1] = c[1];
  } else {
    out.cells.fill(cells_per_axis(N, lattice->sites_per_cell, D));
  }
  out.sites = lattice->sites_per_cell;
  double unit_volume = 1.0;  // box volume for lattice constant 1
  for (int k = 0; k < D; ++k) {
    out.sites *= out.cells[k];
    unit_volume *= static_cast<double>(out.cells[k]) * lattice->cell_shape[k];
  }
  const double ratio = volume / unit_volume;
  out.lattice_constant = D == 3 ? std::cbrt(ratio) : std::sqrt(ratio);
  for (int k = 0; k < D; ++k) {
    out.box[k] = static_cast<double>(out.cells[k]) * lattice->cell_shape[k] * out.lattice_constant;
  }
  out.nearest_neighbour = lattice->nearest_neighbour * out.lattice_constant;
  return out;
}

template <int D>
bool fits_lattice(const Layout<D>& layout, double dmax) {
  return layout.lattice == nullptr || dmax <= layout.nearest_neighbour;
}

template <int D>
bool fits_cell_list(const Layout<D>& layout, double dmax) {
  for (int k = 0; k < D; ++k) {
    if (layout.box[k] < 3.0 * dmax) return false;
  }
  return true;
}

template <int D>
std::string cells_text(const Layout<D>& layout) {
  std::string s = fmt::format("{}", layout.cells[0]);
  for (int k = 1; k < D; ++k) s += fmt::format("x{}", layout.cells[k]);
  return s;
}

std::string lattice_text(const LatticeSpec* lattice) {
  return lattice == nullptr ? std::string("random insertion")
                            : fmt::format("a {} lattice", lattice->name);
}

// The species list of the run, validated.
std::vector<SpeciesConfig> effective_species(const SystemConfig& system) {
  if (system.species.empty()) return {SpeciesConfig{}};
  double total = 0.0;
  for (std::size_t s = 0; s < system.species.size(); ++s) {
    const auto& sp = system.species[s];
    const auto bad = [&](std::string_view key, double v, std::string_view need) {
      return InputError(
          fmt::format("system.species[{}].{} = {} is invalid: must be {}", s, key, v, need));
    };
    if (!(std::isfinite(sp.diameter) && sp.diameter > 0.0)) {
      throw bad("diameter", sp.diameter, "finite and > 0");
    }
    if (!(std::isfinite(sp.mass) && sp.mass > 0.0)) throw bad("mass", sp.mass, "finite and > 0");
    if (!(std::isfinite(sp.fraction) && sp.fraction >= 0.0)) {
      throw bad("fraction", sp.fraction, "finite and >= 0");
    }
    total += sp.fraction;
  }
  if (!(total > 0.0) || !std::isfinite(total)) {
    throw InputError("system.species: the fractions must not all be zero");
  }
  return system.species;
}

template <int D>
void place_on_lattice(const Layout<D>& layout, InitialState<D>& state) {
  const LatticeSpec& lat = *layout.lattice;
  const std::uint64_t N = state.position.size();
  const std::uint64_t whole = layout.sites / N, part = layout.sites % N;
  for (std::uint64_t i = 0; i < N; ++i) {
    poll_stop(i);
    // Site floor(i * sites / N), without overflow (N < 2^32): occupied sites evenly spread.
    const std::uint64_t site = i * whole + (i * part) / N;
    std::uint64_t cell = site / lat.sites_per_cell;
    const auto& basis = lat.basis[site % lat.sites_per_cell];
    for (int k = 0; k < D; ++k) {
      const std::uint64_t ck = cell % layout.cells[k];
      cell /= layout.cells[k];
      const double frac = static_cast<double>(ck) + basis[k] + 0.25;  // quarter-cell offset
      state.position[i][k] = frac * lat.cell_shape[k] * layout.lattice_constant;
    }
  }
}

// The voxels of a periodic grid that may still hold free space for the current insertion
// diameter. Voxels found to lie entirely inside one exclusion sphere are dropped, and when
// insertion gets hard every live voxel is split into 2^D children (Zhang & Torquato, PRE 88,
// 053312 (2013)). All live voxels have the same size, so sampling a live voxel uniformly and
// then a point uniformly inside it is uniform over the free space - exactly random sequential
// insertion - while wasting far fewer attempts near jamming.
template <int D>
class VoxelSampler {
 public:
  static constexpr int kMaxLevel = 12;

  // Voxels of edge >= side, at most max_voxels of them (wider voxels if needed).
  VoxelSampler(const std::array<double, D>& box, double side, std::size_t max_voxels) : box_(box) {
    double total = 1.0;
    for (int k = 0; k < D; ++k) total *= std::max(1.0, std::floor(box[k] / side));
    if (total > static_cast<double>(max_voxels)) {
      side = std::pow(box_volume<D>(box) / static_cast<double>(max_voxels),
                      1.0 / static_cast<double>(D));
    }
    std::uint64_t voxels = 1;
    for (int k = 0; k < D; ++k) {
      m_[k] = static_cast<std::uint64_t>(
          std::min(std::max(1.0, std::floor(box[k] / side)), static_cast<double>(max_voxels)));
      h_[k] = box[k] / static_cast<double>(m_[k]);
      voxels *= m_[k];
    }
    live_.resize(voxels);
    for (std::uint64_t v = 0; v < voxels; ++v) {
      poll_stop(v);
      live_[v] = v;
    }
  }

  std::size_t size() const { return live_.size(); }
  bool empty() const { return live_.empty(); }
  std::size_t pick(std::mt19937_64& rng) const { return uniform_below(rng, live_.size()); }
  std::uint64_t voxel(std::size_t slot) const { return live_[slot]; }

  void kill(std::size_t slot) {
    live_[slot] = live_.back();
    live_.pop_back();
  }

  std::array<double, D> point_in(std::uint64_t voxel, std::mt19937_64& rng) const {
    std::array<double, D> x{};
    for (int k = 0; k < D; ++k) {
      const double c = static_cast<double>(voxel % m_[k]);
      voxel /= m_[k];
      x[k] = wrap_into_box((c + uniform01(rng)) * h_[k], box_[k]);
    }
    return x;
  }

  std::array<double, D> centre(std::uint64_t voxel) const {
    std::array<double, D> x{};
    for (int k = 0; k < D; ++k) {
      x[k] = (static_cast<double>(voxel % m_[k]) + 0.5) * h_[k];
      voxel /= m_[k];
    }
    return x;
  }

  // True when every point of the voxel centred at `c` is closer than `radius` to `point`
  // (minimum image).
  bool covered(const std::array<double, D>& c, const std::array<double, D>& point,
               double radius) const {
    double far2 = 0.0;
    for (int k = 0; k < D; ++k) {
      double dx = point[k] - c[k];
      dx = minimum_image(dx, box_[k]);
      const double far = std::abs(dx) + 0.5 * h_[k];
      far2 += far * far;
    }
    return far2 < radius * radius;
  }

  // Whether a refinement may be tried: below the deepest level, ids still fit, and the live
  // voxels have halved since the last refinement that had to be abandoned.
  bool can_refine() const {
    std::uint64_t total = 1;  // voxel ids of the next level must fit in 64 bits
    for (int k = 0; k < D; ++k) total *= m_[k];
    return level_ < kMaxLevel && live_.size() <= retry_below_ &&
           total <= (std::numeric_limits<std::uint64_t>::max() >> (D + 1));
  }

  struct Sphere {
    std::array<double, D> centre;
    double radius;
  };

  // Splits every live voxel into 2^D and keeps the children not covered by a single exclusion
  // sphere; gather(point, spheres) appends the exclusion spheres that may contain `point` (those
  // of the particles in the cell-grid neighbourhood). Abandoned (nothing changes)
  // when more than max_live children would survive: skipped at once when a sample says so,
  // otherwise after the full pass, and then not tried again before the live voxels have halved.
  template <class Gather>
  void refine(Gather&& gather, std::size_t max_live) {
    VoxelSampler finer(box_);
    for (int k = 0; k < D; ++k) {
      finer.m_[k] = 2 * m_[k];
      finer.h_[k] = 0.5 * h_[k];
    }
    finer.level_ = level_ + 1;
    std::vector<Sphere> near;
    const auto children = [&](std::uint64_t v, auto&& visit) {
      near.clear();
      // The centre of v is a corner of every child, so a sphere covering a child contains it:
      // the spheres near that one point are all the candidates.
      gather(centre(v), near);
      std::array<std::uint64_t, D> c{};
      for (int k = 0; k < D; ++k) {
        c[k] = 2 * (v % m_[k]);
        v /= m_[k];
      }
      for (std::uint64_t child = 0; child < (std::uint64_t{1} << D); ++child) {
        std::uint64_t id = 0;
        std::array<double, D> child_centre{};
        for (int k = D - 1; k >= 0; --k) {
          const std::uint64_t ck = c[k] + ((child >> k) & 1);
          id = id * finer.m_[k] + ck;
          child_centre[k] = (static_cast<double>(ck) + 0.5) * finer.h_[k];
        }
        const bool dead = std::any_of(near.begin(), near.end(), [&](const Sphere& sphere) {
          return finer.covered(child_centre, sphere.centre, sphere.radius);
        });
        if (!dead) visit(id);
      }
    };
    // Estimate the survivors from an evenly spread sample before doing all the work.
    constexpr std::size_t kSample = 256;
    if (live_.size() > 4 * kSample) {
      std::size_t survivors = 0;
      for (std::size_t s = 0; s < kSample; ++s) {
        children(live_[s * (live_.size() / kSample)], [&](std::uint64_t) { ++survivors; });
      }
      if (static_cast<double>(survivors) * static_cast<double>(live_.size() / kSample) >
          static_cast<double>(max_live)) {
        return;  // cheap to try again later, when more particles cover more voxels
      }
    }
    bool too_many = false;
    for (std::size_t s = 0; s < live_.size() && !too_many; ++s) {
      if ((s & 0xfffu) == 0xfffu) throw_if_stop_requested();  // up to 16 N voxels, 2^D children
      children(live_[s], [&](std::uint64_t id) {
        if (finer.live_.size() >= max_live) {
          too_many = true;
        } else {
          finer.live_.push_back(id);
        }
      });
    }
    if (too_many) {
      retry_below_ = live_.size() / 2;
      return;
    }
    *this = std::move(finer);
  }

 private:
  explicit VoxelSampler(const std::array<double, D>& box) : box_(box) {}

  std::array<double, D> box_;
  std::array<std::uint64_t, D> m_{};  // voxels per axis at the current level
  std::array<double, D> h_{};         // voxel edges
  int level_ = 0;
  std::size_t retry_below_ = std::numeric_limits<std::size_t>::max();
  std::vector<std::uint64_t> live_;  // live voxel ids (x fastest) at the current level
};

// Random sequential insertion in the order of the particles (largest diameters first).
template <int D>
// class_width: particles (sorted by decreasing diameter) whose diameters lie within this
// fraction of the first of a class share one voxel sampler (0: one per distinct diameter); a
// voxel is dropped only when it is covered for the class's smallest diameter, so the sampled
// points stay uniform over the free space of every particle of the class.
void insert_randomly(const Layout<D>& layout, double eta, InitialState<D>& state,
                     std::mt19937_64& rng, double class_width) {
  const std::size_t N = state.position.size();
  InsertionGrid<D> grid(layout.box, state.diameter);
  // Memory: at most 8 N voxel ids at the start of a diameter class, 16 N after refinements.
  const std::size_t max_voxels = std::max<std::size_t>(8 * N, 1024);
  std::optional<VoxelSampler<D>> voxels;
  std::uint64_t tries = 0, hits = 0;  // since the last (re)start or refinement of the voxels
  double class_floor = 0.0, class_smallest = 0.0;
  const auto fail = [&](std::size_t i, std::string_view why) {
    return InputError(fmt::format(
        "system.packing_fraction = {} could not be reached by random insertion: particle {} of "
        "{} {}; use a lower packing fraction or a lattice ({}) and let the run melt it",
        eta, i + 1, N, why, lattice_list(D, false)));
  };
  // run.log's set-up lines (500 000 spheres at 0.4 take two minutes).
  const std::string step = fmt::format("random insertion of {} particles", N);
  const auto report = [&](std::size_t placed) {
    if (setup_listened()) report_setup_progress(step, fmt::format("{} placed", placed));
  };
  report(0);
  for (std::size_t i = 0; i < N; ++i) {
    // SIGINT ends a long insertion (near jamming one particle may take 10^6 tries, see below).
    if ((i & 1023u) == 1023u) {
      throw_if_stop_requested();
      report(i);
    }
    const double di = state.diameter[i];
    // Whether the exclusion zone (for the class's smallest diameter) of one placed particle
    // covers the voxel.
    const auto covered = [&](std::uint64_t voxel) {
      const std::array<double, D> c = voxels->centre(voxel);
      return grid.for_each_near(c, class_smallest, [&](std::uint32_t j) {
        return voxels->covered(c, state.position[j], 0.5 * (class_smallest + state.diameter[j]));
      });
    };
    // The exclusion spheres (for diameter di) of the placed particles near a point.
    const auto gather = [&](const std::array<double, D>& point,
                            std::vector<typename VoxelSampler<D>::Sphere>& out) {
      grid.for_each_near(point, di, [&](std::uint32_t j) {
        out.push_back({state.position[j], 0.5 * (di + state.diameter[j])});
        return false;
      });
    };
    if (i == 0 || di < class_floor) {
      // Exclusion radii depend on the inserted diameter: start over with all voxels live.
      class_floor = class_width > 0.0 ? (1.0 - class_width) * di : di;
      std::size_t last = i;
      while (last + 1 < N && state.diameter[last + 1] >= class_floor) ++last;
      class_smallest = state.diameter[last];
      voxels.emplace(layout.box, 0.5 * class_smallest, max_voxels);
      tries = hits = 0;
    }
    bool placed = false;
    for (std::uint64_t attempt = 0; attempt < kMaxInsertionAttempts && !placed; ++attempt) {
      if ((attempt & 4095u) == 4095u) {
        throw_if_stop_requested();
        report(i);
      }
      if (voxels->empty()) throw fail(i, "found the box jammed");
      const std::size_t slot = voxels->pick(rng);
      const std::uint64_t voxel = voxels->voxel(slot);
      const std::array<double, D> x = voxels->point_in(voxel, rng);
      ++tries;
      const bool is_free = !grid.for_each_near(x, di, [&](std::uint32_t j) {
        return pair_overlap<D>(layout.box, x, state.position[j], di, state.diameter[j]) > 0;
      });
      if (is_free) {
        state.position[i] = x;
        grid.insert(static_cast<std::uint32_t>(i), x);
        placed = true;
        ++hits;
        continue;
      }
      if (covered(voxel)) voxels->kill(slot);
      // Acceptance below 1/8 over a fair sample: split the live voxels.
      if (tries >= voxels->size() + 256 && 8 * hits < tries && voxels->can_refine()) {
        voxels->refine(gather, 2 * max_voxels);
        tries = hits = 0;
      }
    }
    if (!placed) {
      throw fail(i, fmt::format("found no free space in {} attempts", kMaxInsertionAttempts));
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Chains.

// Coordinates of site s (0 <= s < n^D) of the snake path through an n^D grid: the last axis
// is the slowest; within each layer the path of the lower axes runs forwards on even layers and
// backwards on odd ones, so consecutive sites always differ by 1 along exactly one axis.
template <int D>
std::array<std::uint64_t, D> snake_site(std::uint64_t s, std::uint64_t n) {
  std::array<std::uint64_t, D> c{};
  std::uint64_t layer = 1;  // sites per layer of the axes below k
  for (int k = 0; k < D - 1; ++k) layer *= n;
  for (int k = D - 1; k >= 0; --k) {
    c[k] = s / layer;
    s %= layer;
    if (c[k] % 2 == 1) s = layer - 1 - s;
    if (k > 0) layer /= n;
  }
  return c;
}

// Site coordinates along one axis, (c + 1/2) a, each rounded up where needed so that the
// computed distance between neighbours is never below a; and the number of sites that fit in
// [0, L) with the gap across the periodic boundary (computed as minimum_image does) >= a. At
// most 2^20 sites per axis (more than N needs; at absurdly low densities the chains then fill
// only the low corner of the box).
std::vector<double> chain_axis(double L, double a) {
  constexpr double kMaxSitesPerAxis = 1 << 20;
  std::vector<double> x;
  const auto n = static_cast<std::uint64_t>(std::min(std::floor(L / a), kMaxSitesPerAxis));
  x.reserve(n);
  for (std::uint64_t c = 0; c < n; ++c) {
    double v = (static_cast<double>(c) + 0.5) * a;
    if (c > 0) {
      v = std::max(v, x.back() + a);
      while (v - x.back() < a) v = std::nextafter(v, std::numeric_limits<double>::infinity());
    }
    x.push_back(v);
  }
  const auto gap_ok = [&] {
    if (x.size() < 2) return x.empty() || x[0] < L;
    const double last = x.back();
    return last < L && std::abs(minimum_image(last - x[0], L)) >= a &&
           std::abs(minimum_image(x[0] - last, L)) >= a;
  };
  while (!x.empty() && !gap_ok()) x.pop_back();
  return x;
}

// Sites per axis of the grid a box of edge L holds at spacing a.
std::uint64_t chain_sites_per_axis(double L, double a) {
  return chain_axis(L, a).size();
}

template <int D>
std::uint64_t power(std::uint64_t n) {
  std::uint64_t p = 1;
  for (int k = 0; k < D; ++k) {
    if (n != 0 && p > std::numeric_limits<std::uint64_t>::max() / n) {
      return std::numeric_limits<std::uint64_t>::max();
    }
    p *= n;
  }
  return p;
}

template <int D>
InitialState<D> make_chain_state(const SystemConfig& system,
                                 const std::vector<SpeciesConfig>& species, std::uint64_t N,
                                 double eta, std::mt19937_64& rng) {
  const std::uint64_t L = system.chain_length;
  if (N % L != 0) {
    throw InputError(
        fmt::format("system.particles ({}) must be a multiple of system.chain_length ({})", N, L));
  }
  double dmax = 0.0;
  for (const auto& s : species) dmax = std::max(dmax, s.diameter);
  const double spacing = system.chain_spacing;
  if (!(std::isfinite(spacing) && spacing >= 0.0)) {
    throw InputError(fmt::format(
        "system.chain_spacing = {} is invalid: must be finite and >= 0 (0: the largest diameter)",
        spacing));
  }
  const double a = spacing == 0.0 ? dmax : spacing;
  if (a < dmax) {
    throw InputError(fmt::format(
        "system.chain_spacing = {} is smaller than the largest diameter {}: bonded neighbours "
        "would overlap",
        spacing, dmax));
  }
  const Layout<D> layout = make_layout<D>(species, N, eta, nullptr);
  if (!fits_cell_list(layout, dmax)) {
    constexpr std::uint64_t kScan = 1'000'000;
    std::uint64_t needed = 0;
    for (std::uint64_t n = N + L; n <= N + kScan && n < kNoParticle; n += L) {
      if (fits_cell_list(make_layout<D>(species, n, eta, nullptr), dmax)) {
        needed = n;
        break;
      }
    }
    const std::string need_text = needed != 0
                                      ? fmt::format("at least {} particles are needed", needed)
                                      : fmt::format("more than {} particles are needed", N + kScan);
    throw InputError(fmt::format(
        "system.particles = {} is too few for packing fraction {} with chains: the box edge "
        "{:.6g} is shorter than 3 x the largest diameter {:.6g} (the cell list needs 3 cells per "
        "axis); {}",
        N, eta, layout.box[0], dmax, need_text));
  }
  const std::vector<double> axis = chain_axis(layout.box[0], a);
  const std::uint64_t n = axis.size();
  const std::uint64_t sites = power<D>(n);
  if (sites < N) {
    // The smallest grid holding N sites, m per axis, needs a box edge of m a.
    std::uint64_t m = 1;
    while (power<D>(m) < N) ++m;
    const double edge = static_cast<double>(m) * a;
    double largest = round_down_6(layout.solid_volume / std::pow(edge, D));
    for (int tries = 0; tries < 64; ++tries) {
      const double Lb = D == 3 ? std::cbrt(layout.solid_volume / largest)
                               : std::sqrt(layout.solid_volume / largest);
      if (chain_sites_per_axis(Lb, a) >= m) break;
      largest = round_down_6(largest * (1.0 - 1e-6));
    }
    throw InputError(fmt::format(
        "system.packing_fraction = {} is too high for {} chains of {} beads at spacing {:.6g}: "
        "the box (edge {:.6g}) holds {} sites per axis, {} in all; the largest possible is "
        "{:.6g}",
        eta, N / L, L, a, layout.box[0], n, sites, largest));
  }

  InitialState<D> state;
  state.box = layout.box;
  for (const auto& s : species) state.species_names.push_back(s.name);
  state.species.reserve(N);
  for (std::size_t s = 0; s < species.size(); ++s) {
    state.species.insert(state.species.end(), layout.counts[s], static_cast<std::uint32_t>(s));
  }
  shuffle(state.species, rng);
  state.diameter.resize(N);
  state.mass.resize(N);
  for (std::size_t i = 0; i < N; ++i) {
    poll_stop(i);
    state.diameter[i] = species[state.species[i]].diameter;
    state.mass[i] = species[state.species[i]].mass;
  }
  // Chain c starts at path site floor(c S / C): consecutive chains at least L sites apart.
  const std::uint64_t chains = N / L;
  const std::uint64_t whole = sites / chains, part = sites % chains;
  state.position.resize(N);
  for (std::uint64_t c = 0; c < chains; ++c) {
    // floor(c * sites / chains) without overflow
    const std::uint64_t first = c * whole + (c * part) / chains;  // c, part < chains < 2^32
    for (std::uint64_t b = 0; b < L; ++b) {
      const auto site = snake_site<D>(first + b, n);
      for (int k = 0; k < D; ++k) state.position[c * L + b][k] = axis[site[k]];
    }
  }
  state.bond_types = {"backbone"};
  state.bonds.reserve(chains * (L - 1));
  for (std::uint64_t c = 0; c < chains; ++c) {
    for (std::uint64_t b = 0; b + 1 < L; ++b) {
      const auto i = static_cast<std::uint32_t>(c * L + b);
      state.bonds.push_back(Bond{i, i + 1, 0});
    }
  }
  assign_maxwell_boltzmann_velocities(state, system.temperature, rng);
  return state;
}
}  // namespace

std::vector<std::uint64_t> largest_remainder_counts(const std::vector<double>& weights,
                                                    std::uint64_t total) {
  double sum = 0.0;
  for (double w : weights) {
    if (!(w >= 0.0) || !std::isfinite(w)) {
      throw std::invalid_argument("largest_remainder_counts: weights must be finite and >= 0");
    }
    sum += w;
  }
  if (!(sum > 0.0) || !std::isfinite(sum)) {
    throw std::invalid_argument("largest_remainder_counts: the weights sum to zero");
  }
  const std::size_t S = weights.size();
  std::vector<std::uint64_t> counts(S);
  std::vector<double> remainder(S);
  std::uint64_t assigned = 0;
  for (std::size_t s = 0; s < S; ++s) {
    const double quota = static_cast<double>(total) * (weights[s] / sum);
    const double whole = std::min(std::floor(quota), static_cast<double>(total));
    counts[s] = static_cast<std::uint64_t>(whole);
    remainder[s] = quota - whole;
    assigned += counts[s];
  }
  std::vector<std::size_t> order(S);
  for (std::size_t s = 0; s < S; ++s) order[s] = s;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return remainder[a] > remainder[b]; });
  // Round-off can leave the floors summing to a little more than `total`: take back from the
  // smallest remainders.
  for (std::size_t m = S; assigned > total && m-- > 0;) {
    const std::size_t s = order[m];
    const std::uint64_t take = std::min(counts[s], assigned - total);
    counts[s] -= take;
    assigned -= take;
  }
  for (std::size_t m = 0; assigned < total; m = (m + 1) % S) {
    if (weights[order[m]] > 0.0) {
      ++counts[order[m]];
      ++assigned;
    }
  }
  return counts;
}

template <int D>
double packing_fraction(const InitialState<D>& state) {
  double solid = 0.0;
  for (double d : state.diameter) solid += particle_volume<D>(d);
  return solid / box_volume<D>(state.box);
}

// Particles in order of decreasing diameter (ties keep their order): random insertion places
// the largest first. Before positions exist.
template <int D>
void sort_by_diameter(InitialState<D>& state) {
  const std::size_t n = state.diameter.size();
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return state.diameter[a] > state.diameter[b];
  });
  const InitialState<D> old = state;
  for (std::size_t i = 0; i < n; ++i) {
    state.species[i] = old.species[order[i]];
    state.diameter[i] = old.diameter[order[i]];
    state.mass[i] = old.mass[order[i]];
  }
}

// One factor of the size distribution (mean 1, relative standard deviation delta;
// docs/config.md, system.size_distribution).
double size_factor(SizeDistribution kind, double delta, std::mt19937_64& rng,
                   NormalSource& normal) {
  switch (kind) {
    case SizeDistribution::kUniform:
      return 1.0 + std::sqrt(3.0) * delta * (2.0 * uniform01(rng) - 1.0);
    case SizeDistribution::kGaussian:
      for (;;) {  // truncated to (0, 2): symmetric, so the mean stays 1
        const double x = 1.0 + delta * normal(rng);
        if (x > 0.0 && x < 2.0) return x;
      }
    case SizeDistribution::kLognormal: {
      const double s2 = std::log1p(delta * delta);
      return std::exp(-0.5 * s2 + std::sqrt(s2) * normal(rng));
    }
    case SizeDistribution::kNone:
      break;
  }
  return 1.0;
}

// Each species' drawn diameters (its diameter times the distribution's factors), `counts[s]`
// of them in the order drawn (a lattice takes them so; random insertion sorts the particles);
// empty without a distribution.
std::vector<std::vector<double>> draw_diameters(const SystemConfig& system,
                                                const std::vector<SpeciesConfig>& species,
                                                const std::vector<std::uint64_t>& counts,
                                                std::mt19937_64& rng) {
  const SizeDistribution kind = size_distributions().at(system.size_distribution);
  if (kind == SizeDistribution::kNone) return {};
  std::vector<std::vector<double>> out(species.size());
  NormalSource normal;
  for (std::size_t s = 0; s < species.size(); ++s) {
    out[s].reserve(counts[s]);
    for (std::uint64_t k = 0; k < counts[s]; ++k) {
      poll_stop(k);
      out[s].push_back(species[s].diameter * size_factor(kind, system.polydispersity, rng, normal));
    }
  }
  return out;
}

template <int D>
InitialState<D> make_initial_state(const SystemConfig& system, std::mt19937_64& rng, RunKind kind) {
  static_assert(D == 2 || D == 3);
  if (system.dimension != D) {
    throw std::invalid_argument(fmt::format(
        "make_initial_state<{}> called with system.dimension = {}", D, system.dimension));
  }
  const std::vector<SpeciesConfig> species = effective_species(system);
  const std::uint64_t N = system.particles;
  if (N < 1 || N >= kNoParticle) {
    throw InputError(
        fmt::format("system.particles = {} is invalid: must be in [1, {}]", N, kNoParticle - 1));
  }
  const double eta = system.packing_fraction;
  if (!(eta > 0.0 && eta < 1.0)) {
    throw InputError(
        fmt::format("system.packing_fraction = {} is invalid: must be in (0, 1)", eta));
  }
  if (!(std::isfinite(system.temperature) && system.temperature >= 0.0)) {
    throw InputError(fmt::format("system.temperature = {} is invalid: must be finite and >= 0",
                                 system.temperature));
  }

  // Before anything is allocated: a state too large for this machine would otherwise fill its
  // memory for minutes and end in std::bad_alloc (or the kernel's OOM killer).
  require_memory(estimated_run_bytes(N, D, kind), fmt::format("system.particles = {}", N));

  if (system.chain_length > 0) return make_chain_state<D>(system, species, N, eta, rng);

  const std::string name =
      system.lattice.empty() ? std::string(D == 3 ? "fcc" : "hex") : system.lattice;
  const LatticeSpec* lattice = nullptr;
  if (name != "random") {
    for (const auto& l : kLattices) {
      if (l.dimension == D && l.name == name) lattice = &l;
    }
    if (lattice == nullptr) {
      throw InputError(fmt::format("system.lattice = \"{}\" is not a {}D lattice; use one of {}",
                                   name, D, lattice_list(D, true)));
    }
  }
  double dmax = 0.0;
  for (const auto& s : species) dmax = std::max(dmax, s.diameter);
  // A size distribution: the diameters are drawn first, so that the box holds exactly the
  // packing fraction asked of the diameters drawn.
  std::vector<std::vector<double>> drawn;
  double drawn_volume = 0.0;
  {
    std::vector<double> fractions;
    for (const auto& sp : species) fractions.push_back(sp.fraction);
    drawn = draw_diameters(system, species, largest_remainder_counts(fractions, N), rng);
    for (const auto& per_species : drawn) {
      for (double d : per_species) {
        drawn_volume += particle_volume<D>(d);
        dmax = std::max(dmax, d);
      }
    }
  }

  if (lattice == nullptr) {
    const double limit = D == 3 ? kRandomMaxPacking3 : kRandomMaxPacking2;
    if (eta > limit) {
      throw InputError(fmt::format(
          "system.packing_fraction = {} is too high for random insertion, which jams near {} in "
          "{}D; use at most {} or a lattice ({}) and let the run melt it",
          eta, D == 3 ? 0.38 : 0.547, D, limit, lattice_list(D, false)));
    }
  }

  const Layout<D> layout = make_layout<D>(species, N, eta, lattice, drawn_volume);
  const bool lattice_fits = fits_lattice(layout, dmax);
  if (!fits_cell_list(layout, dmax)) {
    // The smallest larger N whose box is wide enough and whose lattice fits the diameters (a
    // lattice never fits above its close-packed packing fraction: no search then).
    constexpr std::uint64_t kScan = 1'000'000;
    const bool hopeless = lattice != nullptr && eta > lattice->close_packed;
    std::uint64_t needed = 0;
    for (std::uint64_t n = N + 1; !hopeless && n <= N + kScan && n < kNoParticle; ++n) {
      poll_stop(n - N);
      const Layout<D> trial = make_layout<D>(species, n, eta, lattice);
      if (fits_lattice(trial, dmax) && fits_cell_list(trial, dmax)) {
        needed = n;
        break;
      }
    }
    // When the lattice does not fit either and no N helps, the packing fraction is the problem.
    if (lattice_fits || needed != 0) {
      const std::string need_text =
          needed != 0 ? fmt::format("at least {} particles are needed", needed)
                      : fmt::format("more than {} particles are needed", N + kScan);
      double shortest = layout.box[0];
      for (int k = 1; k < D; ++k) shortest = std::min(shortest, layout.box[k]);
      throw InputError(fmt::format(
          "system.particles = {} is too few for packing fraction {} on {}: the box edge {:.6g} "
          "is shorter than 3 x the largest diameter {:.6g} (the cell list needs 3 cells per "
          "axis); {}",
          N, eta, lattice_text(lattice), shortest, dmax, need_text));
    }
  }
  if (!lattice_fits) {
    const double ratio = layout.nearest_neighbour / dmax;
    const double largest = round_down_6(eta * (D == 3 ? ratio * ratio * ratio : ratio * ratio));
    std::string filling = fmt::format("{} cells", cells_text(layout));
    std::string full_hint;
    if (layout.sites != N) {
      // Partly filled: the nearest-neighbour distance is that of the full lattice, so point at
      // the particle number that fills it.
      filling += fmt::format(", {} sites", layout.sites);
      const Layout<D> full = make_layout<D>(species, layout.sites, eta, lattice);
      const double r = full.nearest_neighbour / dmax;
      full_hint = fmt::format(" ({:.6g} with {} particles, which fill the lattice)",
                              round_down_6(eta * (D == 3 ? r * r * r : r * r)), layout.sites);
    }
    throw InputError(fmt::format(
        "system.packing_fraction = {} is impossible on a {} lattice with {} particles ({}): the "
        "nearest-neighbour distance {:.6g} is smaller than the largest diameter {:.6g}; the "
        "largest possible is {:.6g}{}",
        eta, lattice->name, N, filling, layout.nearest_neighbour, dmax, largest, full_hint));
  }

  InitialState<D> state;
  state.box = layout.box;
  for (const auto& s : species) state.species_names.push_back(s.name);
  state.position.resize(N);
  state.species.reserve(N);
  if (lattice != nullptr) {
    // Species spread over the sites at random: a homogeneous mixture.
    for (std::size_t s = 0; s < species.size(); ++s) {
      state.species.insert(state.species.end(), layout.counts[s], static_cast<std::uint32_t>(s));
    }
    shuffle(state.species, rng);
  } else {
    // Largest diameters first (ties: species order).
    std::vector<std::size_t> order(species.size());
    for (std::size_t s = 0; s < order.size(); ++s) order[s] = s;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return species[a].diameter > species[b].diameter;
    });
    for (std::size_t s : order) {
      state.species.insert(state.species.end(), layout.counts[s], static_cast<std::uint32_t>(s));
    }
  }
  state.diameter.resize(N);
  state.mass.resize(N);
  std::vector<std::size_t> next_drawn(species.size(), 0);
  for (std::size_t i = 0; i < N; ++i) {
    const std::uint32_t sp = state.species[i];
    state.diameter[i] = drawn.empty() ? species[sp].diameter : drawn[sp][next_drawn[sp]++];
    state.mass[i] = species[sp].mass;
  }
  if (!drawn.empty() && lattice == nullptr) sort_by_diameter(state);  // the largest inserted first
  if (lattice != nullptr) {
    place_on_lattice(layout, state);
  } else {
    insert_randomly(layout, eta, state, rng, drawn.empty() ? 0.0 : 0.05);
    sort_spatially(state);  // neighbours close in memory: fewer cache misses in the engine
  }
  assign_maxwell_boltzmann_velocities(state, system.temperature, rng);
  std::vector<bool> fixed;
  for (const SpeciesConfig& sp : species) fixed.push_back(sp.fixed);
  rest_fixed_grains(state, fixed, system.temperature);
  return state;
}

template <int D>
void sort_spatially(InitialState<D>& state) {
  const std::size_t n = state.position.size();
  if (n == 0) return;
  // Cells as wide as the largest diameter: the engine's own neighbour cells.
  const double width = *std::max_element(state.diameter.begin(), state.diameter.end());
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keys(n);
  for (std::size_t i = 0; i < n; ++i) {
    poll_stop(i);
    std::uint64_t key = 0;
    for (int k = D - 1; k >= 0; --k) {
      const auto along =
          static_cast<std::uint64_t>(std::max(1.0, std::floor(state.box[k] / width)));
      const auto c = static_cast<std::uint64_t>(std::max(0.0, state.position[i][k] / width));
      key = key * along + std::min(c, along - 1);
    }
    keys[i] = {key, static_cast<std::uint32_t>(i)};
  }
  std::sort(keys.begin(), keys.end());
  throw_if_stop_requested();
  InitialState<D> sorted = state;
  for (std::size_t i = 0; i < n; ++i) {
    poll_stop(i);
    const std::uint32_t from = keys[i].second;
    sorted.position[i] = state.position[from];
    sorted.species[i] = state.species[from];
    sorted.diameter[i] = state.diameter[from];
    sorted.mass[i] = state.mass[from];
    if (!state.velocity.empty()) sorted.velocity[i] = state.velocity[from];
  }
  if (!state.bonds.empty()) {
    std::vector<std::uint32_t> new_index(n);
    for (std::size_t i = 0; i < n; ++i) new_index[keys[i].second] = static_cast<std::uint32_t>(i);
    for (Bond& b : sorted.bonds) {
      b.i = new_index[b.i];
      b.j = new_index[b.j];
    }
  }
  state = std::move(sorted);
}

template void sort_spatially<2>(InitialState<2>&);
template void sort_spatially<3>(InitialState<3>&);

template <int D>
void assign_maxwell_boltzmann_velocities(InitialState<D>& state, double kT, std::mt19937_64& rng) {
  if (!(std::isfinite(kT) && kT >= 0.0)) {
    throw InputError(
        fmt::format("system.temperature = {} is invalid: must be finite and >= 0", kT));
  }
  const std::size_t N = state.mass.size();
  if (state.position.size() != N) {
    throw std::invalid_argument("assign_maxwell_boltzmann_velocities: mass and position sizes");
  }
  for (double m : state.mass) {
    if (!(std::isfinite(m) && m > 0.0)) {
      throw std::invalid_argument("assign_maxwell_boltzmann_velocities: masses must be > 0");
    }
  }
  state.velocity.assign(N, std::array<double, D>{});
  if (N == 0) return;
  NormalSource normal;
  for (std::size_t i = 0; i < N; ++i) {
    poll_stop(i);
    const double sd = std::sqrt(kT / state.mass[i]);
    for (int k = 0; k < D; ++k) state.velocity[i][k] = sd * normal(rng);
  }
  CompensatedSum total_mass;
  for (double m : state.mass) total_mass.add(m);
  // Two passes: the second removes the round-off residue of the first.
  for (int pass = 0; pass < 2; ++pass) {
    std::array<CompensatedSum, D> momentum{};
    for (std::size_t i = 0; i < N; ++i) {
      poll_stop(i);
      for (int k = 0; k < D; ++k) momentum[k].add(state.mass[i] * state.velocity[i][k]);
    }
    for (int k = 0; k < D; ++k) {
      const double v_cm = momentum[k].value() / total_mass.value();
      for (std::size_t i = 0; i < N; ++i) state.velocity[i][k] -= v_cm;
    }
  }
  CompensatedSum ke;
  for (std::size_t i = 0; i < N; ++i) {
    for (int k = 0; k < D; ++k) ke.add(state.mass[i] * state.velocity[i][k] * state.velocity[i][k]);
  }
  const double twice_ke = ke.value();
  if (N < 2 || kT == 0.0 || !(twice_ke > 0.0)) {
    state.velocity.assign(N, std::array<double, D>{});
    return;
  }
  const double scale = std::sqrt(kT * D * static_cast<double>(N - 1) / twice_ke);
  for (auto& v : state.velocity) {
    for (int k = 0; k < D; ++k) v[k] *= scale;
  }
}

// Fixed grains start at rest; they take up momentum, so the particles that move keep what they
// drew and share the temperature kT over all their D N_mobile degrees of freedom.
template <int D>
void rest_fixed_grains(InitialState<D>& state, const std::vector<bool>& fixed_species, double kT) {
  const auto fixed = [&](std::size_t i) {
    return state.species[i] < fixed_species.size() && fixed_species[state.species[i]];
  };
  const std::size_t N = state.velocity.size();
  std::size_t mobile = 0;
  for (std::size_t i = 0; i < N; ++i) {
    if (fixed(i)) {
      state.velocity[i] = std::array<double, D>{};
    } else {
      ++mobile;
    }
  }
  if (mobile == N) return;
  CompensatedSum ke;
  for (std::size_t i = 0; i < N; ++i)
    for (int k = 0; k < D; ++k) ke.add(state.mass[i] * state.velocity[i][k] * state.velocity[i][k]);
  if (mobile == 0 || kT == 0.0 || !(ke.value() > 0.0)) {
    for (auto& v : state.velocity) v = std::array<double, D>{};
    return;
  }
  const double scale = std::sqrt(kT * D * static_cast<double>(mobile) / ke.value());
  for (auto& v : state.velocity)
    for (int k = 0; k < D; ++k) v[k] *= scale;
}

namespace {

// The pair whose overlap scores highest by measure(overlap, d_i, d_j) (> 0 for overlap > 0)
// over all overlapping pairs; 0 and kNoParticle when none overlaps. max_overlap's engine.
template <int D, class Measure>
double worst_pair(const std::array<double, D>& box, const std::vector<std::array<double, D>>& pos,
                  const std::vector<double>& diameter, std::uint32_t* worst_i,
                  std::uint32_t* worst_j, bool interruptible, const Measure& measure) {
  if (worst_i != nullptr) *worst_i = kNoParticle;
  if (worst_j != nullptr) *worst_j = kNoParticle;
  if (pos.size() != diameter.size()) {
    throw std::invalid_argument("max_overlap: positions and diameters differ in size");
  }
  if (pos.size() >= kNoParticle) throw std::invalid_argument("max_overlap: too many particles");
  for (int k = 0; k < D; ++k) {
    if (!(box[k] > 0.0) || !std::isfinite(box[k])) {
      throw std::invalid_argument("max_overlap: box edges must be finite and > 0");
    }
  }
  const std::size_t N = pos.size();
  double dmax = 0.0;
  for (std::size_t i = 0; i < N; ++i) {
    for (int k = 0; k < D; ++k) {
      if (!std::isfinite(pos[i][k]))
        throw std::invalid_argument("max_overlap: non-finite position");
    }
    if (!std::isfinite(diameter[i]))
      throw std::invalid_argument("max_overlap: non-finite diameter");
    dmax = std::max(dmax, diameter[i]);
  }
  if (N < 2 || !(dmax > 0.0)) return 0.0;

  InsertionGrid<D> grid(box, diameter);
  for (std::size_t i = 0; i < N; ++i) grid.insert(static_cast<std::uint32_t>(i), pos[i]);
  double worst = 0.0;
  for (std::size_t i = 0; i < N; ++i) {
    if (interruptible) poll_stop(i);
    grid.for_each_near(pos[i], diameter[i], [&](std::uint32_t j) {
      if (j <= i) return false;  // each pair once: j's cell is visited once from i's cell
      const double ov = pair_overlap<D>(box, pos[i], pos[j], diameter[i], diameter[j]);
      if (!(ov > 0.0)) return false;
      const double score = measure(ov, diameter[i], diameter[j]);
      if (score > worst) {
        worst = score;
        if (worst_i != nullptr) *worst_i = static_cast<std::uint32_t>(i);
        if (worst_j != nullptr) *worst_j = j;
      }
      return false;
    });
  }
  return worst;
}

// Along the bounded axes the positions are moved into a box padded by three largest diameters
// beyond their extent, so that the periodic search sees no pair through the wrap-around (the
// distance through it is at least 3 d_max): the same pairs and distances as without images.
template <int D, class Measure>
double worst_pair(const std::array<double, D>& box, const std::array<bool, D>& periodic,
                  const std::vector<std::array<double, D>>& pos,
                  const std::vector<double>& diameter, std::uint32_t* worst_i,
                  std::uint32_t* worst_j, bool interruptible, const Measure& measure) {
  if (std::all_of(periodic.begin(), periodic.end(), [](bool p) { return p; }) || pos.empty())
    return worst_pair<D>(box, pos, diameter, worst_i, worst_j, interruptible, measure);
  double dmax = 0.0;
  for (const double d : diameter) dmax = std::max(dmax, std::isfinite(d) ? d : 0.0);
  std::array<double, D> padded = box;
  std::vector<std::array<double, D>> moved = pos;
  for (int k = 0; k < D; ++k) {
    if (periodic[k]) continue;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& x : pos) {
      lo = std::min(lo, x[k]);
      hi = std::max(hi, x[k]);
    }
    if (!std::isfinite(lo) || !std::isfinite(hi))
      throw std::invalid_argument("max_overlap: non-finite position");
    for (auto& x : moved) x[k] = x[k] - lo + dmax;
    padded[k] = (hi - lo) + 3.0 * dmax + (dmax > 0.0 ? 0.0 : 1.0);
  }
  return worst_pair<D>(padded, moved, diameter, worst_i, worst_j, interruptible, measure);
}

// Scores of worst_pair.
inline double overlap_itself(double overlap, double, double) {
  return overlap;
}
inline double overlap_per_smaller_radius(double overlap, double di, double dj) {
  return overlap / (0.5 * std::min(di, dj));
}

}  // namespace

template <int D>
double max_overlap(const std::array<double, D>& box, const std::vector<std::array<double, D>>& pos,
                   const std::vector<double>& diameter, std::uint32_t* worst_i,
                   std::uint32_t* worst_j, bool interruptible) {
  return worst_pair<D>(box, pos, diameter, worst_i, worst_j, interruptible, overlap_itself);
}

template <int D>
double max_overlap(const std::array<double, D>& box, const std::array<bool, D>& periodic,
                   const std::vector<std::array<double, D>>& pos,
                   const std::vector<double>& diameter, std::uint32_t* worst_i,
                   std::uint32_t* worst_j, bool interruptible) {
  return worst_pair<D>(box, periodic, pos, diameter, worst_i, worst_j, interruptible,
                       overlap_itself);
}

template <int D>
double max_relative_overlap(const std::array<double, D>& box, const std::array<bool, D>& periodic,
                            const std::vector<std::array<double, D>>& pos,
                            const std::vector<double>& diameter, std::uint32_t* worst_i,
                            std::uint32_t* worst_j, bool interruptible) {
  return worst_pair<D>(box, periodic, pos, diameter, worst_i, worst_j, interruptible,
                       overlap_per_smaller_radius);
}

template <int D>
double max_overlap_bruteforce(const std::array<double, D>& box, const std::array<bool, D>& periodic,
                              const std::vector<std::array<double, D>>& pos,
                              const std::vector<double>& diameter) {
  if (pos.size() != diameter.size()) {
    throw std::invalid_argument("max_overlap_bruteforce: positions and diameters differ in size");
  }
  double worst = 0.0;
  for (std::size_t i = 0; i < pos.size(); ++i) {
    for (std::size_t j = i + 1; j < pos.size(); ++j) {
      worst = std::max(worst,
                       pair_overlap<D>(box, pos[i], pos[j], diameter[i], diameter[j], &periodic));
    }
  }
  return worst;
}

template <int D>
double max_overlap_bruteforce(const std::array<double, D>& box,
                              const std::vector<std::array<double, D>>& pos,
                              const std::vector<double>& diameter) {
  std::array<bool, D> periodic;
  periodic.fill(true);
  return max_overlap_bruteforce<D>(box, periodic, pos, diameter);
}

#define KAIROS_INSTANTIATE(D)                                                                     \
  template double packing_fraction<D>(const InitialState<D>&);                                    \
  template InitialState<D> make_initial_state<D>(const SystemConfig&, std::mt19937_64&, RunKind); \
  template void rest_fixed_grains<D>(InitialState<D>&, const std::vector<bool>&, double);         \
  template void assign_maxwell_boltzmann_velocities<D>(InitialState<D>&, double,                  \
                                                       std::mt19937_64&);                         \
  template double max_overlap<D>(                                                                 \
      const std::array<double, D>&, const std::vector<std::array<double, D>>&,                    \
      const std::vector<double>&, std::uint32_t*, std::uint32_t*, bool);                          \
  template double max_overlap<D>(const std::array<double, D>&, const std::array<bool, D>&,        \
                                 const std::vector<std::array<double, D>>&,                       \
                                 const std::vector<double>&, std::uint32_t*, std::uint32_t*,      \
                                 bool);                                                           \
  template double max_relative_overlap<D>(                                                        \
      const std::array<double, D>&, const std::array<bool, D>&,                                   \
      const std::vector<std::array<double, D>>&, const std::vector<double>&, std::uint32_t*,      \
      std::uint32_t*, bool);                                                                      \
  template double max_overlap_bruteforce<D>(const std::array<double, D>&,                         \
                                            const std::vector<std::array<double, D>>&,            \
                                            const std::vector<double>&);                          \
  template double max_overlap_bruteforce<D>(                                                      \
      const std::array<double, D>&, const std::array<bool, D>&,                                   \
      const std::vector<std::array<double, D>>&, const std::vector<double>&);

KAIROS_INSTANTIATE(2)
KAIROS_INSTANTIATE(3)
#undef KAIROS_INSTANTIATE

}  // namespace kairos

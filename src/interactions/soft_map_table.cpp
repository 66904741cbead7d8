#include "interactions/soft_map_table.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <iterator>
#include <limits>
#include <mutex>
#include <random>
#include <stdexcept>
#include <thread>

#include "core/error.hpp"
#include "core/stop_flag.hpp"
#include "interactions/parameter_domain.hpp"

namespace kairos {
namespace {

// ---------------------------------------------------------------------------------------------
// Constants of the method. Any change to them (or to what is stored) changes the tables: bump
// kFormatVersion so that cached files are rebuilt.

constexpr std::uint32_t kFormatVersion = 1;
constexpr char kMagic[8] = {'K', 'A', 'I', 'R', 'O', 'S', 'M', 'T'};
constexpr std::uint32_t kByteOrderMark = 0x01020304;
constexpr double kLogMinRatio = -4.0;       // u_min: log10 of the smallest v_t/v_n tabulated
constexpr double kBelowLogMinRatio = -8.0;  // check points below the table: u in [-8, -4)
constexpr double kNodeTolerance = 1e-13;    // collision_map's tolerance for nodes and check points
constexpr double kInitialSpacing = 0.25;    // of u and w, before refinement
// A hair of padding around the ranges, so that a collision exactly at a range's end (whose log10
// the caller computes with its own rounding) is inside.
constexpr double kPad = 1e-9;
constexpr long kMaxNodes = 1L << 21;  // 48 MiB of data
constexpr int kStored = 3;            // ln eps_t, ln(-eps_rdot), ln eps_phi
constexpr double kMinTolerance = 1e-10, kMaxTolerance = 0.1;

double end_coefficient(SoftModel model) {
  return model == SoftModel::LinearDashpot ? 1.0 : 1.5;
}

void require_positive(double x, const char* field) {
  kairos::require_positive(x, field, "soft map table: ");
}

// ---------------------------------------------------------------------------------------------
// Cubic Lagrange interpolation on a uniform grid: the 4 nodes j..j+3 around position s (in units of
// the spacing, 0 <= s <= n - 1, n >= 4), centred where possible and shifted inwards at the ends; t
// = s - j lies in [1, 2] inside and in [0, 1] or [2, 3] at the ends.

inline int stencil_start(double s, int n, double& t) {
  const int j = std::clamp(static_cast<int>(s) - 1, 0, n - 4);
  t = s - j;
  return j;
}

inline void cubic_weights(double t, double w[4]) {
  const double t1 = t - 1.0, t2 = t - 2.0, t3 = t - 3.0;
  w[0] = -(t1 * t2 * t3) * (1.0 / 6.0);
  w[1] = (t * t2 * t3) * 0.5;
  w[2] = -(t * t1 * t3) * 0.5;
  w[3] = (t * t1 * t2) * (1.0 / 6.0);
}

// ---------------------------------------------------------------------------------------------
// Work spread over threads; the calling thread takes part and is the one that reports progress.
// Every chunk polls the stop flag: a SIGINT ends a build within a chunk's time (its Interrupted
// is rethrown on the calling thread like any other error).

template <class F>
void parallel_for(std::size_t n, int threads, const F& f,
                  const std::function<void(double)>& progress) {
  constexpr std::size_t kChunk = 8;
  std::atomic<std::size_t> next{0}, done{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  const auto work = [&](bool reports) {
    for (;;) {
      const std::size_t begin = next.fetch_add(kChunk);
      if (begin >= n || failed.load()) return;
      const std::size_t end = std::min(n, begin + kChunk);
      try {
        throw_if_stop_requested();
        for (std::size_t i = begin; i < end; ++i) f(i);
      } catch (...) {
        const std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
        failed = true;
        return;
      }
      const std::size_t now = done.fetch_add(end - begin) + (end - begin);
      if (reports && progress) progress(static_cast<double>(now) / static_cast<double>(n));
    }
  };
  const std::size_t extra =
      std::min<std::size_t>(static_cast<std::size_t>(std::max(threads, 1) - 1), n / kChunk);
  std::vector<std::thread> pool;
  pool.reserve(extra);
  for (std::size_t k = 0; k < extra; ++k) pool.emplace_back(work, false);
  work(true);
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

// The relative error of one component (see the header): 0/0 counts as 0.
double relative_error(double table, double direct) {
  if (table == direct) return 0.0;
  return std::abs(table - direct) / std::abs(direct);
}

void component_errors(const CollisionMap& table, const CollisionMap& direct, double err[4]) {
  err[0] = relative_error(table.eps_t, direct.eps_t);
  err[1] = relative_error(table.eps_rdot, direct.eps_rdot);
  err[2] = relative_error(table.eps_phi, direct.eps_phi);
  err[3] = relative_error(table.end_overlap, direct.end_overlap);
}

// --------------------------------------------------------------------------------------------- The
// file format: little helpers over a byte string, native byte order (checked by a mark).

class Writer {
 public:
  template <class T>
  void put(T value) {
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    out_.append(bytes, sizeof(T));
  }
  void put_bytes(const char* p, std::size_t n) { out_.append(p, n); }
  std::string& str() { return out_; }

 private:
  std::string out_;
};

class Reader {
 public:
  Reader(const std::string& bytes, const std::filesystem::path& file)
      : bytes_(bytes), file_(file) {}
  template <class T>
  T get(const char* what) {
    if (bytes_.size() - pos_ < sizeof(T)) fail(fmt::format("truncated (in {})", what));
    T value;
    std::memcpy(&value, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }
  std::size_t position() const { return pos_; }
  std::size_t remaining() const { return bytes_.size() - pos_; }
  [[noreturn]] void fail(const std::string& why) const {
    throw InputError(fmt::format("soft map table file '{}': {}", file_.string(), why));
  }

 private:
  const std::string& bytes_;
  const std::filesystem::path& file_;
  std::size_t pos_ = 0;
};

std::uint64_t fnv1a(const char* p, std::size_t n) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (std::size_t i = 0; i < n; ++i) {
    h ^= static_cast<unsigned char>(p[i]);
    h *= 0x100000001b3ULL;
  }
  return h;
}

// The key: everything that determines a table's content. It opens the file, and its hash names the
// file.
std::string key_bytes(const SoftTableSpec& s, int check_points, std::uint64_t seed) {
  Writer w;
  w.put_bytes(kMagic, sizeof kMagic);
  w.put(kFormatVersion);
  w.put(kByteOrderMark);
  w.put(static_cast<std::uint32_t>(s.law.model));
  w.put(s.law.stiffness);
  w.put(s.law.damping);
  w.put(s.reduced_mass);
  w.put(s.contact_distance);
  w.put(s.min_normal_speed);
  w.put(s.max_normal_speed);
  w.put(s.max_tangential_ratio);
  w.put(static_cast<std::uint32_t>(s.head_on ? 1 : 0));
  w.put(s.tolerance);
  w.put(static_cast<std::int32_t>(check_points));
  w.put(seed);
  return std::move(w.str());
}

std::string read_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(fmt::format("soft map table file '{}': cannot open", file.string()));
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad())
    throw InputError(fmt::format("soft map table file '{}': cannot read", file.string()));
  return bytes;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Validation and geometry.

void SoftMapTable::validate(const SoftTableSpec& spec) {
  const SoftContactLaw& law = spec.law;
  const bool dashpot = law.model == SoftModel::LinearDashpot;
  if (!dashpot && law.model != SoftModel::ViscoelasticHertz)
    throw InputError(
        "soft map table: law.model must be the linear dashpot or "
        "viscoelastic Hertz");
  require_positive(law.stiffness, dashpot ? "law.stiffness (the spring constant k)"
                                          : "law.stiffness (the Hertz prefactor rho)");
  if (!(std::isfinite(law.damping) && law.damping >= 0.0))
    throw InputError(
        fmt::format("soft map table: law.damping ({}) must be finite and >= 0, got {}",
                    dashpot ? "the dashpot coefficient gamma" : "the dissipative time constant A",
                    law.damping));
  require_positive(spec.reduced_mass, "reduced_mass");
  require_positive(spec.contact_distance, "contact_distance");
  require_positive(spec.min_normal_speed, "min_normal_speed");
  require_positive(spec.max_normal_speed, "max_normal_speed");
  if (!(spec.max_normal_speed > spec.min_normal_speed))
    throw InputError(
        fmt::format("soft map table: max_normal_speed ({}) must "
                    "exceed min_normal_speed ({})",
                    spec.max_normal_speed, spec.min_normal_speed));
  if (!spec.head_on && !(std::isfinite(spec.max_tangential_ratio) &&
                         spec.max_tangential_ratio > std::pow(10.0, kLogMinRatio)))
    throw InputError(
        fmt::format("soft map table: max_tangential_ratio must be "
                    "finite and > 1e-4, got {}",
                    spec.max_tangential_ratio));
  if (!(spec.tolerance >= kMinTolerance && spec.tolerance <= kMaxTolerance))
    throw InputError(fmt::format("soft map table: tolerance must be in [{}, {}], got {}",
                                 kMinTolerance, kMaxTolerance, spec.tolerance));
}

ReducedCollision SoftMapTable::reduced_at(double u, double w) const {
  ReducedCollision r;
  r.model = spec_.law.model;
  r.l_tilde = std::pow(10.0, w);
  r.c_phi = spec_.head_on ? 0.0 : r.l_tilde * std::pow(10.0, u);
  r.c_dis = spec_.law.model == SoftModel::LinearDashpot ? c_dis_
                                                        : c_dis_ / std::sqrt(std::sqrt(r.l_tilde));
  return r;
}

void SoftMapTable::set_grid(const SoftTableGrid& grid) {
  grid_ = grid;
  inv_u_step_ = grid.nu > 1 ? 1.0 / grid.u_step : 0.0;
  inv_w_step_ = 1.0 / grid.w_step;
  // (less a rounding, so that v_t/v_n computed as exactly 10^u_min is on the table)
  min_ratio_ = grid.nu > 1 ? std::pow(10.0, grid.u_min) * (1.0 - 1e-12) : 0.0;
  report_.nodes = grid.nu > 1 ? std::vector<int>{grid.nu, grid.nw} : std::vector<int>{grid.nw};
}

// ---------------------------------------------------------------------------------------------
// Lookup: the hot path (once per collision in the engine): two logarithms, 16 (or 4) nodes, three
// exponentials, no allocation.

void SoftMapTable::interpolate(double su, double sw, double out[3]) const {
  double tw, ww[4];
  const int jw = stencil_start(sw, grid_.nw, tw);
  cubic_weights(tw, ww);
  if (grid_.nu == 1) {
    const double* p = data_.data() + static_cast<std::size_t>(jw) * kStored;
    for (int c = 0; c < kStored; ++c)
      out[c] = ww[0] * p[c] + ww[1] * p[kStored + c] + ww[2] * p[2 * kStored + c] +
               ww[3] * p[3 * kStored + c];
    return;
  }
  double tu, wu[4];
  const int ju = stencil_start(su, grid_.nu, tu);
  cubic_weights(tu, wu);
  double acc[kStored] = {0.0, 0.0, 0.0};
  for (int b = 0; b < 4; ++b) {
    const double* p =
        data_.data() + (static_cast<std::size_t>(jw + b) * static_cast<std::size_t>(grid_.nu) +
                        static_cast<std::size_t>(ju)) *
                           kStored;
    for (int c = 0; c < kStored; ++c) {
      const double row = wu[0] * p[c] + wu[1] * p[kStored + c] + wu[2] * p[2 * kStored + c] +
                         wu[3] * p[3 * kStored + c];
      acc[c] += ww[b] * row;
    }
  }
  for (int c = 0; c < kStored; ++c) out[c] = acc[c];
}

void SoftMapTable::fill(const double logs[3], const CollisionUnits& units,
                        CollisionMap& map) const {
  const double l = units.reduced.l_tilde;
  const double e = std::exp(logs[1]);
  map.eps_t = std::exp(logs[0]);
  map.eps_rdot = -e;
  map.eps_phi = std::exp(logs[2]);
  map.end_overlap = kappa_ * units.reduced.c_dis * e;
  map.eps_r = (l - map.end_overlap) / l;
  map.eps_phidot = 1.0 / (map.eps_r * map.eps_r);
  map.phi_c = map.eps_phi * units.angle_unit;
  map.steps = 0;
}

bool SoftMapTable::lookup(const CollisionUnits& units, CollisionMap& map) const {
  const ReducedCollision& r = units.reduced;
  // Units of another pair would give a wrong map silently: the check costs a few products.
  const bool same_pair = r.model == spec_.law.model &&
                         (r.model == SoftModel::LinearDashpot
                              ? std::abs(r.c_dis - c_dis_) <= 1e-9 * c_dis_
                              : std::abs((r.c_dis * r.c_dis) * (r.c_dis * r.c_dis) * r.l_tilde -
                                         c_dis4_) <= 1e-8 * c_dis4_);
  if (!same_pair) [[unlikely]]
    throw std::logic_error(
        fmt::format("SoftMapTable::lookup: the collision (model {}, c_dis {}, "
                    "l~ {}) is not of this table's "
                    "pair",
                    static_cast<int>(r.model), r.c_dis, r.l_tilde));
  // Positions a rounding beyond the end nodes (1e-9 of a spacing) count as on them.
  constexpr double kSlack = 1e-9;
  double sw = (std::log10(r.l_tilde) - grid_.w_min) * inv_w_step_;
  if (!(sw >= -kSlack && sw <= grid_.nw - 1 + kSlack)) return false;
  sw = std::clamp(sw, 0.0, static_cast<double>(grid_.nw - 1));
  double su = 0.0;
  if (grid_.nu > 1) {
    const double ratio = r.c_phi / r.l_tilde;
    if (ratio < min_ratio_) {
      if (!report_.clamps_below_min_ratio) return false;
    } else {
      su = (std::log10(ratio) - grid_.u_min) * inv_u_step_;
      if (!(su <= grid_.nu - 1 + kSlack)) return false;
      su = std::clamp(su, 0.0, static_cast<double>(grid_.nu - 1));
    }
  }
  double logs[kStored];
  interpolate(su, sw, logs);
  fill(logs, units, map);
  return true;
}

CollisionMap SoftMapTable::node_map(int i, int j) const {
  if (i < 0 || i >= grid_.nu || j < 0 || j >= grid_.nw)
    throw std::out_of_range(fmt::format("SoftMapTable::node_map: no node ({}, {})", i, j));
  CollisionUnits units;
  units.reduced = reduced_at(grid_.u_min + i * grid_.u_step, grid_.w_min + j * grid_.w_step);
  units.angle_unit = units.reduced.c_phi / (units.reduced.l_tilde * units.reduced.l_tilde);
  CollisionMap map;
  fill(data_.data() + (static_cast<std::size_t>(j) * static_cast<std::size_t>(grid_.nu) +
                       static_cast<std::size_t>(i)) *
                          kStored,
       units, map);
  return map;
}

// ---------------------------------------------------------------------------------------------
// Building.

struct SoftMapTableBuilder {
  struct Point {
    CollisionUnits units;
    CollisionMap direct;
  };

  static CollisionUnits units_of(const SoftMapTable& t, double u, double w) {
    CollisionUnits units;
    units.reduced = t.reduced_at(u, w);
    units.angle_unit = units.reduced.c_phi / (units.reduced.l_tilde * units.reduced.l_tilde);
    return units;
  }

  static void node_logs(const ReducedCollision& r, double* out) {
    MapOptions options;
    options.tolerance = kNodeTolerance;
    options.interruptible = true;
    const CollisionMap m = collision_map(r, options);
    if (!(m.eps_t > 0.0 && m.eps_rdot < 0.0 && m.eps_phi > 0.0))
      throw std::logic_error(
          fmt::format("soft map table: unexpected map at c_phi = {}, l~ = {}, c_dis = {}: "
                      "eps_t {}, "
                      "eps_rdot {}, eps_phi {}",
                      r.c_phi, r.l_tilde, r.c_dis, m.eps_t, m.eps_rdot, m.eps_phi));
    out[0] = std::log(m.eps_t);
    out[1] = std::log(-m.eps_rdot);
    out[2] = std::log(m.eps_phi);
  }

  // Largest error per component over points (lookup against direct); +inf if one falls outside (it
  // must not).
  static void max_errors(const SoftMapTable& t, const std::vector<Point>& points, double err[4]) {
    std::fill(err, err + 4, 0.0);
    for (const Point& p : points) {
      CollisionMap m;
      double e[4];
      if (t.lookup(p.units, m)) {
        component_errors(m, p.direct, e);
      } else {
        std::fill(e, e + 4, std::numeric_limits<double>::infinity());
      }
      for (int c = 0; c < 4; ++c) err[c] = std::max(err[c], e[c]);
    }
  }

  // The largest error (over the four components) of interpolating along one axis alone (axis 0: u,
  // 1: w): points at random positions along it, on random node lines of the other.
  static double axis_error(const SoftMapTable& t, int axis, const SoftTableBuildOptions& options,
                           int level, int threads) {
    const SoftTableGrid& g = t.grid_;
    std::mt19937_64 rng(options.seed ^
                        (0x9e3779b97f4a7c15ULL * static_cast<std::uint64_t>(2 * level + axis + 1)));
    const auto uniform01 = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
    std::vector<Point> points(static_cast<std::size_t>(std::max(50, options.check_points / 4)));
    for (Point& p : points) {
      double u = g.u_min + (g.nu - 1) * g.u_step * uniform01();
      double w = g.w_min + (g.nw - 1) * g.w_step * uniform01();
      if (axis == 0) {
        w = g.w_min + g.w_step * static_cast<double>(rng() % static_cast<std::uint64_t>(g.nw));
      } else {
        u = g.u_min + g.u_step * static_cast<double>(rng() % static_cast<std::uint64_t>(g.nu));
      }
      p.units = units_of(t, u, w);
    }
    MapOptions tight;
    tight.tolerance = kNodeTolerance;
    tight.interruptible = true;
    parallel_for(
        points.size(), threads,
        [&](std::size_t k) { points[k].direct = collision_map(points[k].units.reduced, tight); },
        nullptr);
    double err[4];
    max_errors(t, points, err);
    return *std::max_element(err, err + 4);
  }

  static SoftMapTable build(const SoftTableSpec& spec, const SoftTableBuildOptions& options) {
    SoftMapTable::validate(spec);
    if (options.threads < 0)
      throw InputError(
          fmt::format("soft map table: threads must be >= 0, got {}", options.threads));
    if (options.check_points < 10 || options.check_points > 10'000'000)
      throw InputError(fmt::format("soft map table: check_points must be in [10, 1e7], got {}",
                                   options.check_points));
    const auto start = std::chrono::steady_clock::now();
    const int threads = options.threads > 0
                            ? options.threads
                            : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
    SoftMapTable t;
    t.spec_ = spec;
    t.check_seed_ = options.seed;
    const SoftContactLaw& law = spec.law;
    t.kappa_ = end_coefficient(law.model);
    if (law.model == SoftModel::LinearDashpot) {
      t.c_dis_ = law.damping / std::sqrt(law.stiffness * spec.reduced_mass);
    } else {
      t.c_dis_ = law.damping * std::sqrt(law.stiffness / spec.reduced_mass) *
                 std::sqrt(std::sqrt(spec.contact_distance));
      t.c_dis4_ = (t.c_dis_ * t.c_dis_) * (t.c_dis_ * t.c_dis_);
    }
    // l~ falls with the impact speed: the fastest collision is at the low end of w.
    const double w_lo = std::log10(
        reduce_collision(law, spec.reduced_mass, spec.contact_distance, spec.max_normal_speed, 0.0)
            .reduced.l_tilde);
    const double w_hi = std::log10(
        reduce_collision(law, spec.reduced_mass, spec.contact_distance, spec.min_normal_speed, 0.0)
            .reduced.l_tilde);
    const double u_lo = kLogMinRatio;
    const double u_hi = std::log10(spec.max_tangential_ratio);
    const double wpad = kPad * std::max(1.0, std::abs(w_lo) + std::abs(w_hi));
    const double upad = kPad * std::max(1.0, std::abs(u_hi));
    const double w_min = w_lo - wpad, w_max = w_hi + wpad;
    const double u_min = u_lo, u_max = u_hi + upad;
    {
      // The deepest contact of the table: head-on at the highest speed.
      ReducedCollision deepest = t.reduced_at(u_min, w_min);
      deepest.c_phi = 0.0;
      try {
        collision_map(deepest);
      } catch (const InputError&) {
        throw InputError(
            fmt::format("soft map table: max_normal_speed = {} is too high for "
                        "this contact: the particles "
                        "would interpenetrate (l~ = {:.4g} at that speed; it "
                        "must exceed about 1, better "
                        "10); lower max_normal_speed or stiffen the law",
                        spec.max_normal_speed, deepest.l_tilde));
      }
    }

    // The check points and their direct maps (computed once, reused at every refinement).
    std::mt19937_64 rng(options.seed);
    const auto uniform = [&](double a, double b) {
      return a + (b - a) * static_cast<double>(rng() >> 11) * 0x1.0p-53;
    };
    std::vector<Point> inside(static_cast<std::size_t>(options.check_points));
    for (Point& p : inside) {
      const double u = spec.head_on ? 0.0 : uniform(u_lo, u_hi);
      p.units = units_of(t, u, uniform(w_lo, w_hi));
    }
    std::vector<Point> below;
    if (!spec.head_on) {
      below.resize(static_cast<std::size_t>(std::max(10, options.check_points / 10)));
      for (std::size_t k = 0; k < below.size(); ++k) {
        // Every fourth exactly head-on (v_t = 0), the others in u in [-8, -4).
        const double u = k % 4 == 0 ? -std::numeric_limits<double>::infinity()
                                    : uniform(kBelowLogMinRatio, kLogMinRatio);
        below[k].units = units_of(t, u, uniform(w_lo, w_hi));
      }
    }
    MapOptions tight;
    tight.tolerance = kNodeTolerance;
    tight.interruptible = true;
    const std::size_t n_check = inside.size() + below.size();
    parallel_for(
        n_check, threads,
        [&](std::size_t k) {
          Point& p = k < inside.size() ? inside[k] : below[k - inside.size()];
          p.direct = collision_map(p.units.reduced, tight);
        },
        options.progress);

    int nu_int = spec.head_on
                     ? 0
                     : std::max(3, static_cast<int>(std::ceil((u_max - u_min) / kInitialSpacing)));
    int nw_int = std::max(3, static_cast<int>(std::ceil((w_max - w_min) / kInitialSpacing)));
    std::vector<double> old_data;
    SoftTableGrid old_grid;
    int u_factor = 1,
        w_factor = 1;  // how the grid was refined from the previous level
    for (int level = 0;; ++level) {
      SoftTableGrid g;
      g.nu = nu_int + 1;
      g.u_min = spec.head_on ? 0.0 : u_min;
      g.u_step = spec.head_on ? 0.0 : (u_max - u_min) / nu_int;
      g.nw = nw_int + 1;
      g.w_min = w_min;
      g.w_step = (w_max - w_min) / nw_int;
      const std::size_t nodes = static_cast<std::size_t>(g.nu) * static_cast<std::size_t>(g.nw);
      std::vector<double> data(nodes * kStored, std::numeric_limits<double>::quiet_NaN());
      std::vector<std::size_t> todo;
      todo.reserve(nodes);
      for (int j = 0; j < g.nw; ++j) {
        for (int i = 0; i < g.nu; ++i) {
          const std::size_t k = static_cast<std::size_t>(j) * static_cast<std::size_t>(g.nu) +
                                static_cast<std::size_t>(i);
          // After a halving, every other node along the halved axes is the previous level's.
          if (level > 0 && j % w_factor == 0 && i % u_factor == 0) {
            const std::size_t k_old =
                static_cast<std::size_t>(j / w_factor) * static_cast<std::size_t>(old_grid.nu) +
                static_cast<std::size_t>(i / u_factor);
            std::copy_n(old_data.data() + k_old * kStored, kStored, data.data() + k * kStored);
          } else {
            todo.push_back(k);
          }
        }
      }
      parallel_for(
          todo.size(), threads,
          [&](std::size_t n) {
            const std::size_t k = todo[n];
            const int i = static_cast<int>(k % static_cast<std::size_t>(g.nu));
            const int j = static_cast<int>(k / static_cast<std::size_t>(g.nu));
            node_logs(t.reduced_at(g.u_min + i * g.u_step, g.w_min + j * g.w_step),
                      data.data() + k * kStored);
          },
          options.progress);
      t.data_ = std::move(data);
      t.set_grid(g);
      t.report_.clamps_below_min_ratio = false;
      double err[4];
      max_errors(t, inside, err);
      std::copy(err, err + 4, t.report_.max_error);
      t.report_.refinements = level;
      if (*std::max_element(err, err + 4) <= spec.tolerance) break;
      // Which axis to halve: the error of interpolating along one axis alone, measured on the other
      // axis's node lines (the map varies about twice as fast along u as along w where grazing sets
      // in, so u usually needs the finer spacing).
      bool refine_u = false, refine_w = true;
      if (!spec.head_on) {
        const double e_u = axis_error(t, 0, options, level, threads);
        const double e_w = axis_error(t, 1, options, level, threads);
        refine_u = e_u > 0.5 * spec.tolerance;
        refine_w = e_w > 0.5 * spec.tolerance;
        if (!refine_u && !refine_w) (e_u >= e_w ? refine_u : refine_w) = true;
      }
      u_factor = refine_u ? 2 : 1;
      w_factor = refine_w ? 2 : 1;
      const long next_nodes =
          static_cast<long>(u_factor * nu_int + 1) * static_cast<long>(w_factor * nw_int + 1);
      // The user's to fix (a tolerance or a range asked for), so an InputError.
      if (next_nodes > kMaxNodes)
        throw InputError(
            fmt::format("soft map table: the tolerance {} is not reached with "
                        "{} nodes (max relative errors "
                        "{:.3g}, {:.3g}, {:.3g}, {:.3g} in eps_t, eps_rdot, "
                        "eps_phi, end_overlap); loosen "
                        "the tolerance (soft.table_tolerance) or narrow the speed range",
                        spec.tolerance, nodes, err[0], err[1], err[2], err[3]));
      old_data = t.data_;
      old_grid = g;
      nu_int *= u_factor;
      nw_int *= w_factor;
    }
    if (spec.head_on) {
      t.report_.clamps_below_min_ratio = true;
    } else {
      t.report_.clamps_below_min_ratio = true;  // measure the clamped lookups
      double err[4];
      max_errors(t, below, err);
      t.report_.below_min_ratio_error = *std::max_element(err, err + 4);
      t.report_.clamps_below_min_ratio = t.report_.below_min_ratio_error <= spec.tolerance;
    }
    t.report_.check_points = options.check_points;
    t.report_.build_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    t.report_.recorded_build_seconds = t.report_.build_seconds;
    if (options.progress) options.progress(1.0);
    return t;
  }

  // --- The file ---

  static std::string serialize(const SoftMapTable& t) {
    Writer w;
    w.str() = key_bytes(t.spec_, t.report_.check_points, t.check_seed_);
    const SoftTableGrid& g = t.grid_;
    w.put(g.u_min);
    w.put(g.u_step);
    w.put(static_cast<std::int32_t>(g.nu));
    w.put(g.w_min);
    w.put(g.w_step);
    w.put(static_cast<std::int32_t>(g.nw));
    const SoftTableReport& r = t.report_;
    w.put(r.recorded_build_seconds);
    for (double e : r.max_error) w.put(e);
    w.put(static_cast<std::int32_t>(r.refinements));
    w.put(static_cast<std::uint32_t>(r.clamps_below_min_ratio ? 1 : 0));
    w.put(r.below_min_ratio_error);
    w.put(static_cast<std::uint64_t>(t.data_.size()));
    for (double v : t.data_) w.put(v);
    const std::uint64_t sum = fnv1a(w.str().data(), w.str().size());
    w.put(sum);
    return std::move(w.str());
  }

  static SoftMapTable parse(const std::string& bytes, const std::filesystem::path& file) {
    Reader in(bytes, file);
    if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
      in.fail("not a Kairos soft map table");
    for (std::size_t k = 0; k < sizeof kMagic; ++k) in.get<char>("magic");
    const auto version = in.get<std::uint32_t>("version");
    if (version != kFormatVersion)
      in.fail(
          fmt::format("format version {}, this Kairos reads version {}", version, kFormatVersion));
    if (in.get<std::uint32_t>("byte order") != kByteOrderMark)
      in.fail("written on a machine of another byte order");
    if (bytes.size() < sizeof(std::uint64_t)) in.fail("truncated");
    std::uint64_t stored_sum;
    std::memcpy(&stored_sum, bytes.data() + bytes.size() - sizeof stored_sum, sizeof stored_sum);
    if (fnv1a(bytes.data(), bytes.size() - sizeof stored_sum) != stored_sum)
      in.fail("checksum mismatch (truncated or damaged)");

    SoftMapTable t;
    SoftTableSpec& s = t.spec_;
    const auto model = in.get<std::uint32_t>("model");
    if (model > static_cast<std::uint32_t>(SoftModel::ViscoelasticHertz)) in.fail("unknown model");
    s.law.model = static_cast<SoftModel>(model);
    s.law.stiffness = in.get<double>("stiffness");
    s.law.damping = in.get<double>("damping");
    s.reduced_mass = in.get<double>("reduced mass");
    s.contact_distance = in.get<double>("contact distance");
    s.min_normal_speed = in.get<double>("min speed");
    s.max_normal_speed = in.get<double>("max speed");
    s.max_tangential_ratio = in.get<double>("max ratio");
    s.head_on = in.get<std::uint32_t>("head-on") != 0;
    s.tolerance = in.get<double>("tolerance");
    t.report_.check_points = in.get<std::int32_t>("check points");
    t.check_seed_ = in.get<std::uint64_t>("seed");
    try {
      SoftMapTable::validate(s);
    } catch (const InputError& e) {
      in.fail(fmt::format("invalid spec ({})", e.what()));
    }
    SoftTableGrid g;
    g.u_min = in.get<double>("grid");
    g.u_step = in.get<double>("grid");
    g.nu = in.get<std::int32_t>("grid");
    g.w_min = in.get<double>("grid");
    g.w_step = in.get<double>("grid");
    g.nw = in.get<std::int32_t>("grid");
    const bool grid_ok =
        std::isfinite(g.u_min) && std::isfinite(g.w_min) && std::isfinite(g.w_step) &&
        g.w_step > 0.0 && g.nw >= 4 && g.nw <= kMaxNodes &&
        (s.head_on ? g.nu == 1
                   : (g.nu >= 4 && g.nu <= kMaxNodes && std::isfinite(g.u_step) && g.u_step > 0.0 &&
                      static_cast<long>(g.nu) * g.nw <= kMaxNodes));
    if (!grid_ok) in.fail("invalid grid");
    SoftTableReport& r = t.report_;
    r.recorded_build_seconds = in.get<double>("report");
    for (double& e : r.max_error) e = in.get<double>("report");
    r.refinements = in.get<std::int32_t>("report");
    r.clamps_below_min_ratio = in.get<std::uint32_t>("report") != 0;
    r.below_min_ratio_error = in.get<double>("report");
    const auto count = in.get<std::uint64_t>("data size");
    const std::uint64_t expected =
        static_cast<std::uint64_t>(g.nu) * static_cast<std::uint64_t>(g.nw) * kStored;
    if (count != expected) in.fail("data size does not match the grid");
    if (in.remaining() != count * sizeof(double) + sizeof(std::uint64_t))
      in.fail("file size does not match the grid");
    t.data_.resize(count);
    for (double& v : t.data_) {
      v = in.get<double>("data");
      if (!std::isfinite(v)) in.fail("non-finite data");
    }
    // Derived members, as build sets them.
    t.kappa_ = end_coefficient(s.law.model);
    if (s.law.model == SoftModel::LinearDashpot) {
      t.c_dis_ = s.law.damping / std::sqrt(s.law.stiffness * s.reduced_mass);
    } else {
      t.c_dis_ = s.law.damping * std::sqrt(s.law.stiffness / s.reduced_mass) *
                 std::sqrt(std::sqrt(s.contact_distance));
      t.c_dis4_ = (t.c_dis_ * t.c_dis_) * (t.c_dis_ * t.c_dis_);
    }
    t.set_grid(g);
    return t;
  }
};

SoftMapTable SoftMapTable::build(const SoftTableSpec& spec, const SoftTableBuildOptions& options) {
  return SoftMapTableBuilder::build(spec, options);
}

// ---------------------------------------------------------------------------------------------
// Files and the cache.

std::filesystem::path SoftMapTable::cache_file_name(const SoftTableSpec& spec,
                                                    const SoftTableBuildOptions& options) {
  const std::string key = key_bytes(spec, options.check_points, options.seed);
  return fmt::format("soft_map_{:016x}.bin", fnv1a(key.data(), key.size()));
}

SoftMapTable SoftMapTable::read_file(const std::filesystem::path& file) {
  SoftMapTable t = SoftMapTableBuilder::parse(read_bytes(file), file);
  t.report_.from_cache = true;
  t.report_.cache_file = file;
  return t;
}

void SoftMapTable::write_file(const std::filesystem::path& file) const {
  const std::string bytes = SoftMapTableBuilder::serialize(*this);
  // A unique temporary name: two runs may build the same table at once; the last rename wins and
  // either file is complete. (Not io/atomic_file: interactions stay below io.)
  static std::atomic<unsigned> counter{0};
  std::filesystem::path tmp = file;
  tmp += fmt::format(".tmp.{}.{}", static_cast<long>(::getpid()), counter.fetch_add(1));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      std::error_code ignored;
      std::filesystem::remove(tmp, ignored);
      throw InputError(
          fmt::format("soft map table: cannot write '{}': {}", tmp.string(), std::strerror(errno)));
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw InputError(
        fmt::format("soft map table: cannot replace '{}': {}", file.string(), ec.message()));
  }
}

SoftMapTable SoftMapTable::load_or_build(const SoftTableSpec& spec,
                                         const std::filesystem::path& cache_dir,
                                         const SoftTableBuildOptions& options) {
  validate(spec);
  std::error_code ec;
  std::filesystem::create_directories(cache_dir, ec);
  if (ec)
    throw InputError(fmt::format("soft map table: cannot create the cache directory '{}': {}",
                                 cache_dir.string(), ec.message()));
  const std::filesystem::path file = cache_dir / cache_file_name(spec, options);
  if (std::filesystem::exists(file, ec)) {
    try {
      const std::string bytes = read_bytes(file);
      // The whole key must match (a hash collision or a stale format is rebuilt).
      const std::string key = key_bytes(spec, options.check_points, options.seed);
      if (bytes.size() >= key.size() && bytes.compare(0, key.size(), key) == 0) {
        SoftMapTable t = SoftMapTableBuilder::parse(bytes, file);
        t.report_.from_cache = true;
        t.report_.build_seconds = 0.0;
        t.report_.cache_file = file;
        return t;
      }
    } catch (const InputError&) {
      // Damaged or unreadable: rebuilt and replaced below.
    }
  }
  SoftMapTable t = build(spec, options);
  t.write_file(file);
  t.report_.cache_file = file;
  return t;
}

std::filesystem::path default_soft_table_cache_dir() {
  const auto env = [](const char* name) -> std::string {
    const char* v = std::getenv(name);
    return v != nullptr ? std::string(v) : std::string();
  };
  if (const std::string d = env("KAIROS_CACHE_DIR"); !d.empty())
    return std::filesystem::path(d) / "soft_tables";
  if (const std::string d = env("XDG_CACHE_HOME"); !d.empty())
    return std::filesystem::path(d) / "kairos" / "soft_tables";
  if (const std::string d = env("HOME"); !d.empty())
    return std::filesystem::path(d) / ".cache" / "kairos" / "soft_tables";
  return std::filesystem::path(".kairos-cache") / "soft_tables";
}

}  // namespace kairos

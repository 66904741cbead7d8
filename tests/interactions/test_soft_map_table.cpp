// Lookup tables of the soft-sphere collision map (src/interactions/soft_map_table.hpp): lookups
// against direct integration (collision_map) at random off-grid points, the ranges, head-on tables
// against the head-on closed forms (docs/physics.md#dashpot-head-on and the sections after it),
// the cache file (round trip, damaged, stale and other-spec files) and input validation. Small
// speed ranges keep the builds short; one table is built at the default tolerance 1e-6.
#include "interactions/soft_map_table.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "input_error_matchers.hpp"

namespace kairos {
namespace {

constexpr double kMu = 0.5, kL = 1.0;

SoftTableSpec dashpot_spec(double c_dis, double v_min, double v_max, double ratio, double tol) {
  SoftTableSpec s;
  const double k = 1e4;
  s.law = SoftContactLaw::linear_dashpot(k, c_dis * std::sqrt(k * kMu));
  s.reduced_mass = kMu;
  s.contact_distance = kL;
  s.min_normal_speed = v_min;
  s.max_normal_speed = v_max;
  s.max_tangential_ratio = ratio;
  s.tolerance = tol;
  return s;
}

// Hertz with c_dis = c_at_1 at v_n = 1 (c_dis = A / T, T = (mu^2 / (rho^2 v))^(1/5)).
SoftTableSpec hertz_spec(double c_at_1, double v_min, double v_max, double ratio, double tol) {
  SoftTableSpec s;
  const double rho = 1e5;
  const double T1 = std::pow(kMu * kMu / (rho * rho), 0.2);
  s.law = SoftContactLaw::viscoelastic_hertz(rho, c_at_1 * T1);
  s.reduced_mass = kMu;
  s.contact_distance = kL;
  s.min_normal_speed = v_min;
  s.max_normal_speed = v_max;
  s.max_tangential_ratio = ratio;
  s.tolerance = tol;
  return s;
}

SoftTableBuildOptions few_checks(int points = 300) {
  SoftTableBuildOptions o;
  o.check_points = points;
  return o;
}

double rel(double a, double b) {
  return a == b ? 0.0 : std::abs(a - b) / std::abs(b);
}

// Random impact velocities within the table's speeds and ratios: the largest relative error of each
// component of lookup() against collision_map, and the errors of the derived fields.
struct Sample {
  double err[4] = {};
  double eps_r_err = 0.0, phidot_err = 0.0, phi_c_err = 0.0;
  int looked_up = 0;
};

Sample sample_errors(const SoftMapTable& table, int n, std::uint64_t seed) {
  const SoftTableSpec& s = table.spec();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Sample out;
  for (int k = 0; k < n; ++k) {
    const double v_n =
        s.min_normal_speed * std::pow(s.max_normal_speed / s.min_normal_speed, unit(rng));
    const double ratio =
        s.head_on ? 0.0
                  : std::pow(10.0, -4.0 + (std::log10(s.max_tangential_ratio) + 4.0) * unit(rng));
    const CollisionUnits units =
        reduce_collision(s.law, s.reduced_mass, s.contact_distance, v_n, ratio * v_n);
    CollisionMap m;
    if (!table.lookup(units, m)) continue;
    ++out.looked_up;
    const CollisionMap d = collision_map(units.reduced);
    const double e[4] = {rel(m.eps_t, d.eps_t), rel(m.eps_rdot, d.eps_rdot),
                         rel(m.eps_phi, d.eps_phi), rel(m.end_overlap, d.end_overlap)};
    for (int c = 0; c < 4; ++c) out.err[c] = std::max(out.err[c], e[c]);
    out.eps_r_err = std::max(out.eps_r_err, rel(m.eps_r, d.eps_r));
    out.phidot_err = std::max(out.phidot_err, rel(m.eps_phidot, d.eps_phidot));
    out.phi_c_err = std::max(out.phi_c_err, rel(m.phi_c, d.phi_c));
  }
  return out;
}

// A fresh sample's maximum may exceed the build's (another sample of the same error field) a
// little: allow a factor 2.
void expect_within_tolerance(const SoftMapTable& table, int n = 400, std::uint64_t seed = 99) {
  const double tol = table.spec().tolerance;
  for (int c = 0; c < 4; ++c)
    EXPECT_LE(table.report().max_error[c], tol) << kSoftTableComponents[c];
  const Sample s = sample_errors(table, n, seed);
  EXPECT_EQ(s.looked_up, n) << "every sampled collision lies in the table";
  for (int c = 0; c < 4; ++c) EXPECT_LE(s.err[c], 2.0 * tol) << kSoftTableComponents[c];
  EXPECT_LE(s.eps_r_err, 2.0 * tol);
  EXPECT_LE(s.phidot_err, 4.0 * tol);
  EXPECT_LE(s.phi_c_err, 2.0 * tol);
}

// A fresh directory under the system's temporary directory, removed at the end of the test.
class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : path_(std::filesystem::temp_directory_path() /
              ("kairos_soft_map_" + name + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// ---------------------------------------------------------------------------------------------
// Accuracy.

TEST(SoftMapTable, DashpotAtDefaultToleranceMatchesDirectIntegration) {
  const SoftTableSpec spec = dashpot_spec(0.2, 1.0, 2.0, 30.0, 1e-6);
  ASSERT_EQ(spec.tolerance, SoftTableSpec{}.tolerance);
  const SoftMapTable table = SoftMapTable::build(spec, few_checks(500));
  ASSERT_EQ(table.report().nodes.size(), 2u);
  EXPECT_FALSE(table.report().from_cache);
  EXPECT_GT(table.report().build_seconds, 0.0);
  expect_within_tolerance(table, 500);
}

TEST(SoftMapTable, DashpotDampingsMatchDirectIntegration) {
  // Elastic, weakly damped, critically damped and overdamped.
  for (double c_dis : {0.0, 0.05, 2.0, 6.0}) {
    SCOPED_TRACE("c_dis = " + std::to_string(c_dis));
    const SoftMapTable table =
        SoftMapTable::build(dashpot_spec(c_dis, 0.5, 2.0, 100.0, 1e-4), few_checks());
    expect_within_tolerance(table, 200);
  }
}

TEST(SoftMapTable, HertzMatchesDirectIntegrationForSeveralK) {
  for (double c_at_1 : {0.0, 0.01, 0.3, 1.5}) {
    SCOPED_TRACE("c_dis(v=1) = " + std::to_string(c_at_1));
    const SoftMapTable table =
        SoftMapTable::build(hertz_spec(c_at_1, 0.3, 3.0, 100.0, 1e-4), few_checks());
    expect_within_tolerance(table, 200);
  }
}

TEST(SoftMapTable, HertzAtTightToleranceMatchesDirectIntegration) {
  const SoftMapTable table =
      SoftMapTable::build(hertz_spec(0.1, 1.0, 2.0, 10.0, 1e-6), few_checks());
  expect_within_tolerance(table, 300);
}

TEST(SoftMapTable, ElasticTablesEndAtZeroOverlapExactly) {
  for (const SoftTableSpec& spec :
       {dashpot_spec(0.0, 1.0, 2.0, 10.0, 1e-4), hertz_spec(0.0, 1.0, 2.0, 10.0, 1e-4)}) {
    const SoftMapTable table = SoftMapTable::build(spec, few_checks());
    const CollisionUnits units = reduce_collision(spec.law, kMu, kL, 1.3, 2.0);
    CollisionMap m;
    ASSERT_TRUE(table.lookup(units, m));
    EXPECT_EQ(m.end_overlap, 0.0);
    EXPECT_EQ(m.eps_r, 1.0);
    EXPECT_EQ(m.eps_phidot, 1.0);
    EXPECT_NEAR(m.eps_rdot, -1.0, 1e-4);
  }
}

TEST(SoftMapTable, NodesHoldTheDirectMap) {
  const SoftMapTable table =
      SoftMapTable::build(hertz_spec(0.2, 1.0, 2.0, 10.0, 1e-3), few_checks());
  const SoftTableGrid& g = table.grid();
  for (const auto& [i, j] :
       {std::pair{0, 0}, std::pair{g.nu - 1, g.nw - 1}, std::pair{g.nu / 2, 1}}) {
    const CollisionMap node = table.node_map(i, j);
    const CollisionMap direct =
        collision_map(table.reduced_at(g.u_min + i * g.u_step, g.w_min + j * g.w_step));
    EXPECT_LE(rel(node.eps_t, direct.eps_t), 1e-11);
    EXPECT_LE(rel(node.eps_rdot, direct.eps_rdot), 1e-11);
    EXPECT_LE(rel(node.eps_phi, direct.eps_phi), 1e-11);
    EXPECT_LE(rel(node.end_overlap, direct.end_overlap), 1e-11);
    EXPECT_LE(rel(node.phi_c, direct.phi_c), 1e-11);
  }
  EXPECT_THROW(table.node_map(g.nu, 0), std::out_of_range);
}

// ---------------------------------------------------------------------------------------------
// Ranges.

TEST(SoftMapTable, OutsideTheTableLookupReturnsFalseAndLeavesTheMap) {
  const SoftTableSpec spec = dashpot_spec(0.2, 1.0, 2.0, 10.0, 1e-3);
  const SoftMapTable table = SoftMapTable::build(spec, few_checks());
  CollisionMap m;
  m.eps_t = 123.0;
  const auto lookup = [&](double v_n, double v_t) {
    return table.lookup(reduce_collision(spec.law, kMu, kL, v_n, v_t), m);
  };
  EXPECT_FALSE(lookup(0.9, 0.5));   // too slow
  EXPECT_FALSE(lookup(2.2, 0.5));   // too fast
  EXPECT_FALSE(lookup(1.5, 16.0));  // too grazing (v_t / v_n > 10)
  EXPECT_EQ(m.eps_t, 123.0);
  EXPECT_TRUE(lookup(1.0, 10.0));  // both range ends are inside
  EXPECT_TRUE(lookup(2.0, 20.0));
}

TEST(SoftMapTable, NearlyHeadOnCollisionsTakeTheEdgeRowWhenTheBuildAllowsIt) {
  const SoftTableSpec spec = hertz_spec(0.2, 1.0, 2.0, 10.0, 1e-6);
  const SoftMapTable table = SoftMapTable::build(spec, few_checks());
  // v_t/v_n < 1e-4 changes the map by about (v_t/v_n)^2 / l~, far below 1e-6.
  ASSERT_TRUE(table.report().clamps_below_min_ratio);
  EXPECT_LE(table.report().below_min_ratio_error, spec.tolerance);
  for (double v_t : {0.0, 1e-9, 1e-5}) {
    const CollisionUnits units = reduce_collision(spec.law, kMu, kL, 1.5, v_t);
    CollisionMap m;
    ASSERT_TRUE(table.lookup(units, m)) << v_t;
    const CollisionMap d = collision_map(units.reduced);
    EXPECT_LE(rel(m.eps_t, d.eps_t), 2e-6);
    EXPECT_LE(rel(m.eps_rdot, d.eps_rdot), 2e-6);
    EXPECT_LE(rel(m.eps_phi, d.eps_phi), 2e-6);
    EXPECT_LE(rel(m.phi_c, d.phi_c), 2e-6);  // 0 for v_t = 0
  }
}

TEST(SoftMapTable, LookupRejectsTheUnitsOfAnotherPair) {
  const SoftTableSpec spec = hertz_spec(0.2, 1.0, 2.0, 10.0, 1e-3);
  const SoftMapTable table = SoftMapTable::build(spec, few_checks());
  CollisionMap m;
  EXPECT_THROW(table.lookup(reduce_collision(spec.law, 2.0 * kMu, kL, 1.5, 0.1), m),
               std::logic_error);
  EXPECT_THROW(
      table.lookup(reduce_collision(SoftContactLaw::linear_dashpot(1e4, 1.0), kMu, kL, 1.5, 0.1),
                   m),
      std::logic_error);
}

// ---------------------------------------------------------------------------------------------
// Head-on tables (walls) against the closed forms (docs/physics.md#dashpot-head-on,
// docs/physics.md#viscoelastic-head-on, docs/physics.md#hertz-contact-time).

TEST(SoftMapTable, DashpotHeadOnTableIsTheClosedForm) {
  for (double c_dis : {0.2, 1.0, 3.0}) {
    SoftTableSpec spec = dashpot_spec(c_dis, 0.01, 10.0, 1.0, 1e-6);
    spec.head_on = true;
    const SoftMapTable table = SoftMapTable::build(spec, few_checks());
    ASSERT_EQ(table.report().nodes.size(), 1u);
    const HeadOn closed = dashpot_head_on_reduced(0.5 * c_dis);
    for (double v : {0.01, 0.3, 10.0}) {
      // A wall: v_t plays no part (the caller passes 0; other values are ignored).
      for (double v_t : {0.0, 5.0 * v}) {
        CollisionMap m;
        ASSERT_TRUE(table.lookup(reduce_collision(spec.law, kMu, kL, v, v_t), m));
        EXPECT_LE(rel(m.eps_t, closed.contact_time), 1e-6) << v;
        EXPECT_LE(rel(-m.eps_rdot, closed.restitution), 1e-6) << v;
        // xi_c = (2 beta / omega_0^2) e v, in units of v T = v / omega_0: c_dis e.
        EXPECT_LE(rel(m.end_overlap, c_dis * closed.restitution), 1e-6) << v;
      }
    }
  }
}

TEST(SoftMapTable, HertzHeadOnTableIsTheClosedForm) {
  // Elastic: Hertz's contact time and e = 1.
  SoftTableSpec elastic = hertz_spec(0.0, 0.1, 10.0, 1.0, 1e-6);
  elastic.head_on = true;
  const SoftMapTable t0 = SoftMapTable::build(elastic, few_checks());
  for (double v : {0.1, 1.0, 10.0}) {
    CollisionMap m;
    ASSERT_TRUE(t0.lookup(reduce_collision(elastic.law, kMu, kL, v, 0.0), m));
    EXPECT_LE(rel(m.eps_t, hertz_contact_time_constant()), 1e-6);
    EXPECT_LE(rel(m.eps_rdot, -1.0), 1e-6);
    EXPECT_EQ(m.end_overlap, 0.0);
  }
  // Viscoelastic, c_dis = A / T from 0.0016 to 0.004 (grows as v^(1/5)): the restitution series to
  // 7th order is exact to ~1e-8 there.
  SoftTableSpec visco = hertz_spec(0.0025, 0.1, 10.0, 1.0, 1e-6);
  visco.head_on = true;
  const SoftMapTable t1 = SoftMapTable::build(visco, few_checks());
  for (double v : {0.1, 1.0, 10.0}) {
    CollisionMap m;
    const CollisionUnits units = reduce_collision(visco.law, kMu, kL, v, 0.0);
    ASSERT_TRUE(t1.lookup(units, m));
    const double x = viscoelastic_series_variable(units.reduced.c_dis);
    EXPECT_LE(rel(-m.eps_rdot, viscoelastic_restitution_series(x, 7)), 2e-6) << v;
    EXPECT_LE(rel(m.end_overlap, 1.5 * units.reduced.c_dis * -m.eps_rdot), 1e-12);
  }
}

// --------------------------------------------------------------------------------------------- The
// cache.

std::string read_all(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_all(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// Lookups of two tables at the same random collisions are bit-identical.
void expect_identical_lookups(const SoftMapTable& a, const SoftMapTable& b) {
  const SoftTableSpec& s = a.spec();
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int k = 0; k < 200; ++k) {
    const double v_n = s.min_normal_speed + (s.max_normal_speed - s.min_normal_speed) * unit(rng);
    const CollisionUnits units =
        reduce_collision(s.law, s.reduced_mass, s.contact_distance, v_n, 3.0 * unit(rng) * v_n);
    CollisionMap ma, mb;
    ASSERT_TRUE(a.lookup(units, ma));
    ASSERT_TRUE(b.lookup(units, mb));
    EXPECT_EQ(std::memcmp(&ma, &mb, sizeof ma), 0);
  }
}

TEST(SoftMapTable, CacheRoundTripGivesBitIdenticalLookups) {
  const TempDir dir("roundtrip");
  const SoftTableSpec spec = hertz_spec(0.2, 1.0, 2.0, 10.0, 1e-4);
  const SoftMapTable built = SoftMapTable::load_or_build(spec, dir.path(), few_checks());
  EXPECT_FALSE(built.report().from_cache);
  ASSERT_TRUE(std::filesystem::exists(built.report().cache_file));
  EXPECT_EQ(built.report().cache_file.parent_path(), dir.path());
  const SoftMapTable loaded = SoftMapTable::load_or_build(spec, dir.path(), few_checks());
  EXPECT_TRUE(loaded.report().from_cache);
  EXPECT_EQ(loaded.report().build_seconds, 0.0);
  EXPECT_EQ(loaded.report().recorded_build_seconds, built.report().build_seconds);
  EXPECT_EQ(loaded.report().nodes, built.report().nodes);
  for (int c = 0; c < 4; ++c) EXPECT_EQ(loaded.report().max_error[c], built.report().max_error[c]);
  expect_identical_lookups(built, loaded);
  // Nothing but the table is left in the directory (no temporary files).
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                          std::filesystem::directory_iterator()),
            1);
}

TEST(SoftMapTable, DamagedOrStaleCacheFilesAreRebuilt) {
  const TempDir dir("damaged");
  const SoftTableSpec spec = dashpot_spec(0.3, 1.0, 2.0, 10.0, 1e-4);
  const SoftMapTable built = SoftMapTable::load_or_build(spec, dir.path(), few_checks());
  const std::filesystem::path file = built.report().cache_file;
  const std::string good = read_all(file);
  ASSERT_GT(good.size(), 200u);

  std::string flipped = good;
  flipped[good.size() / 2] = static_cast<char>(flipped[good.size() / 2] ^ 0x10);
  std::string wrong_version = good;
  wrong_version[8] = static_cast<char>(wrong_version[8] + 1);  // the version follows the magic
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"a flipped bit", flipped},
      {"truncated", good.substr(0, good.size() - 9)},
      {"empty", ""},
      {"another format version", wrong_version},
      {"not a table", std::string(good.size(), 'x')}};
  for (const auto& [what, bytes] : cases) {
    SCOPED_TRACE(what);
    write_all(file, bytes);
    EXPECT_THROW(SoftMapTable::read_file(file), InputError);
    const SoftMapTable rebuilt = SoftMapTable::load_or_build(spec, dir.path(), few_checks());
    EXPECT_FALSE(rebuilt.report().from_cache);
    EXPECT_EQ(read_all(file).size(), good.size()) << "the file is rewritten";
    expect_identical_lookups(built, rebuilt);
    EXPECT_TRUE(SoftMapTable::load_or_build(spec, dir.path(), few_checks()).report().from_cache);
  }
  EXPECT_INPUT_ERROR(SoftMapTable::read_file(dir.path() / "missing.bin"), "cannot open");
  write_all(file, flipped);
  EXPECT_INPUT_ERROR(SoftMapTable::read_file(file), "checksum");
  write_all(file, wrong_version);
  EXPECT_INPUT_ERROR(SoftMapTable::read_file(file), "format version");
}

TEST(SoftMapTable, EverySpecFieldAndCheckSettingNamesItsOwnFile) {
  const SoftTableSpec base = dashpot_spec(0.3, 1.0, 2.0, 10.0, 1e-3);
  const auto name = [](const SoftTableSpec& s, const SoftTableBuildOptions& o = {}) {
    return SoftMapTable::cache_file_name(s, o);
  };
  EXPECT_EQ(name(base), name(base));
  SoftTableBuildOptions more_threads;
  more_threads.threads = 7;
  EXPECT_EQ(name(base), name(base, more_threads));  // does not change the content
  std::vector<SoftTableSpec> variants(9, base);
  variants[0].law.model = SoftModel::ViscoelasticHertz;
  variants[1].law.stiffness *= 2.0;
  variants[2].law.damping *= 2.0;
  variants[3].reduced_mass *= 2.0;
  variants[4].contact_distance *= 2.0;
  variants[5].min_normal_speed *= 0.5;
  variants[6].max_normal_speed *= 2.0;
  variants[7].max_tangential_ratio *= 2.0;
  variants[8].head_on = true;
  SoftTableSpec tighter = base;
  tighter.tolerance = 1e-5;
  variants.push_back(tighter);
  std::vector<std::filesystem::path> names{name(base)};
  for (const auto& v : variants) names.push_back(name(v));
  SoftTableBuildOptions other_seed, other_points;
  other_seed.seed = 2;
  other_points.check_points = 100;
  names.push_back(name(base, other_seed));
  names.push_back(name(base, other_points));
  for (std::size_t a = 0; a < names.size(); ++a)
    for (std::size_t b = a + 1; b < names.size(); ++b)
      EXPECT_NE(names[a], names[b]) << a << " " << b;

  // A file of another spec under this spec's name (a hash collision, a hand copy) is rebuilt.
  const TempDir dir("otherspec");
  SoftTableSpec other = base;
  other.max_normal_speed = 2.5;
  const SoftMapTable t_other = SoftMapTable::load_or_build(other, dir.path(), few_checks());
  std::filesystem::copy_file(t_other.report().cache_file, dir.path() / name(base, few_checks()));
  const SoftMapTable t_base = SoftMapTable::load_or_build(base, dir.path(), few_checks());
  EXPECT_FALSE(t_base.report().from_cache);
  EXPECT_EQ(t_base.spec().max_normal_speed, base.max_normal_speed);
}

// ---------------------------------------------------------------------------------------------
// Validation.

TEST(SoftMapTable, InvalidSpecsThrowInputErrorNamingTheField) {
  const SoftTableSpec good = dashpot_spec(0.2, 1.0, 2.0, 10.0, 1e-4);
  const auto with = [&](auto change) {
    SoftTableSpec s = good;
    change(s);
    return s;
  };
  EXPECT_INPUT_ERROR(SoftMapTable::build(with([](auto& s) { s.law.stiffness = 0.0; })),
                     "law.stiffness");
  EXPECT_INPUT_ERROR(SoftMapTable::build(with([](auto& s) { s.law.damping = -1.0; })),
                     "law.damping");
  EXPECT_INPUT_ERROR(SoftMapTable::build(with([](auto& s) { s.reduced_mass = 0.0; })),
                     "reduced_mass");
  EXPECT_INPUT_ERROR(SoftMapTable::build(with([](auto& s) { s.contact_distance = NAN; })),
                     "contact_distance");
  EXPECT_INPUT_ERROR(SoftMapTable::build(with([](auto& s) { s.min_normal_speed = -1.0; })),
                     "min_normal_speed");
  EXPECT_INPUT_ERROR(SoftMapTable::build(with([](auto& s) { s.max_normal_speed = 0.5; })),
                     "max_normal_speed");
  EXPECT_INPUT_ERROR(SoftMapTable::build(with([](auto& s) { s.max_tangential_ratio = 1e-5; })),
                     "max_tangential_ratio");
  EXPECT_INPUT_ERROR(SoftMapTable::build(with([](auto& s) { s.tolerance = 0.0; })), "tolerance");
  EXPECT_INPUT_ERROR(SoftMapTable::build(with([](auto& s) { s.tolerance = 1e-14; })), "tolerance");
  // So fast that the particles would pass through each other (l~ < 1).
  EXPECT_INPUT_ERROR(SoftMapTable::build(with([](auto& s) { s.max_normal_speed = 1e3; })),
                     "max_normal_speed");
  SoftTableBuildOptions bad;
  bad.check_points = 0;
  EXPECT_INPUT_ERROR(SoftMapTable::build(good, bad), "check_points");
  bad = {};
  bad.threads = -1;
  EXPECT_INPUT_ERROR(SoftMapTable::build(good, bad), "threads");
  const TempDir dir("invalid");
  EXPECT_INPUT_ERROR(
      SoftMapTable::load_or_build(with([](auto& s) { s.reduced_mass = -1.0; }), dir.path()),
      "reduced_mass");
}

TEST(SoftMapTable, ProgressIsReportedUpToOne) {
  SoftTableBuildOptions o = few_checks(100);
  std::vector<double> seen;
  o.progress = [&](double f) { seen.push_back(f); };
  o.threads = 2;
  SoftMapTable::build(dashpot_spec(0.2, 1.0, 2.0, 10.0, 1e-3), o);
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back(), 1.0);
  for (double f : seen) {
    EXPECT_GE(f, 0.0);
    EXPECT_LE(f, 1.0);
  }
}

}  // namespace
}  // namespace kairos

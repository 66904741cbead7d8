// Reference values per interaction (docs/validation.md#reference-values-per-interaction): one
// generic driver for the JSON files of tests/interactions/reference/, after the YAML tests of
// LAMMPS's force styles. Each file names its interaction and holds cases: a pre-collision state
// in, the expected post-collision state out, a tolerance and the source of the numbers, which
// tests/interactions/reference/make_reference.py computes independently of this code from the
// papers' formulas. The driver runs the C++ function the file's `interaction` names, compares
// every expected output (|actual - expected| <= tolerance * max(|expected|, scale)), fails on an
// expected field it did not check, and checks the conservation laws every case must obey:
// momentum for pairs, the energy balance (kinetic change + dissipated = 0 for pairs, = the
// wall's work J.u at a wall, + the step's dU when a step is crossed), angular momentum about the
// contact point for contact collisions.
//
// Adding a case: edit the generator and re-run it. Adding an interaction: a new file and one
// entry in kInteractions below. Each file is one test; ctest discovers a new file's test when
// kairos_tests is next built (the binary itself reads the directory when it starts).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/vec.hpp"
#include "dynamics/collision_time.hpp"
#include "interactions/granular_contact.hpp"
#include "interactions/hard_sphere.hpp"
#include "interactions/soft_contact.hpp"
#include "interactions/step_potential.hpp"

namespace kairos {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// Relative bounds of the conservation checks (round-off of a few operations on O(1) numbers).
constexpr double kMomentumTolerance = 1e-13;
constexpr double kEnergyTolerance = 1e-13;

fs::path reference_directory() {
  return fs::path(KAIROS_SOURCE_DIR) / "tests" / "interactions" / "reference";
}

// The stems of the directory's JSON files, sorted.
std::vector<std::string> reference_files() {
  std::vector<std::string> stems;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(reference_directory(), ec))
    if (entry.path().extension() == ".json") stems.push_back(entry.path().stem().string());
  std::sort(stems.begin(), stems.end());
  return stems;
}

json read_file(const std::string& stem) {
  std::ifstream in(reference_directory() / (stem + ".json"));
  if (!in) throw std::runtime_error("cannot open " + stem + ".json");
  return json::parse(in);
}

// ---------------------------------------------------------------------------------------------
// Reading inputs.

template <int D>
Vec<D> vec_of(const json& j) {
  if (!j.is_array() || j.size() != static_cast<std::size_t>(D))
    throw std::runtime_error("expected a vector of " + std::to_string(D) + " numbers, got " +
                             j.dump());
  Vec<D> a;
  for (std::size_t k = 0; k < a.size(); ++k) a[k] = j[k].get<double>();
  return a;
}

template <int D>
Spin<D> spin_of(const json& j) {
  if constexpr (D == 3) {
    return vec_of<3>(j);
  } else {
    return j.get<double>();
  }
}

NormalRestitution normal_model_of(const json& j) {
  const std::string model = j.at("model");
  if (model == "constant") return NormalRestitution::constant(j.at("e"));
  if (model == "viscoelastic") return NormalRestitution::viscoelastic(j.at("k"));
  if (model == "viscoelastic_from_material")
    return NormalRestitution::viscoelastic_from_material(j.at("dissipative_time"),
                                                         j.at("hertz_rho"), j.at("reduced_mass"));
  if (model == "viscoelastic_at")
    return NormalRestitution::viscoelastic_at(j.at("e_reference"), j.at("reference_speed"));
  if (model == "table")
    return NormalRestitution::table(j.at("speeds").get<std::vector<double>>(),
                                    j.at("values").get<std::vector<double>>());
  throw std::runtime_error("unknown normal restitution model '" + model + "'");
}

TangentialModel tangential_model_of(const json& j) {
  const std::string model = j.at("model");
  if (model == "smooth") return TangentialModel::smooth();
  if (model == "constant") return TangentialModel::constant(j.at("beta"));
  if (model == "walton") return TangentialModel::walton(j.at("friction"), j.at("beta0"));
  throw std::runtime_error("unknown tangential model '" + model + "'");
}

ContactModel contact_model_of(const json& law) {
  ContactModel m;
  m.normal = normal_model_of(law.at("normal"));
  m.tangential = tangential_model_of(law.at("tangential"));
  m.elastic_below_speed = law.value("elastic_below_speed", 0.0);
  return m;
}

// ---------------------------------------------------------------------------------------------
// Comparing outputs and checking the conservation laws of one case.

class Checker {
 public:
  explicit Checker(const json& c)
      : expected_(c.at("expected")),
        tolerance_(c.at("tolerance").get<double>()),
        scale_(c.value("scale", 1.0)) {}

  bool expects(const std::string& key) const { return expected_.contains(key); }
  void scalar(const std::string& key, double actual) {
    if (!expected_.contains(key)) return;
    checked_.insert(key);
    compare(key, actual, expected_.at(key).get<double>());
  }
  template <std::size_t N>
  void vector(const std::string& key, const std::array<double, N>& actual) {
    if (!expected_.contains(key)) return;
    checked_.insert(key);
    const json& e = expected_.at(key);
    if (e.size() != N) {
      ADD_FAILURE() << key << ": expected " << e.size() << " components, the driver has " << N;
      return;
    }
    for (std::size_t k = 0; k < N; ++k)
      compare(key + "[" + std::to_string(k) + "]", actual[k], e[k].get<double>());
  }
  void spin(const std::string& key, double actual) { scalar(key, actual); }
  void spin(const std::string& key, const Vec<3>& actual) { vector(key, actual); }
  void flag(const std::string& key, bool actual) {
    if (!expected_.contains(key)) return;
    checked_.insert(key);
    EXPECT_EQ(actual, expected_.at(key).get<bool>()) << key;
  }
  // A time that may be never: null in the file.
  void time(const std::string& key, double actual) {
    if (!expected_.contains(key)) return;
    if (expected_.at(key).is_null()) {
      checked_.insert(key);
      EXPECT_EQ(actual, kNever) << key << ": expected never";
      return;
    }
    scalar(key, actual);
  }

  // A conservation law: |violation| <= tolerance * scale.
  static void conserved(const std::string& what, double violation, double scale, double tolerance) {
    EXPECT_LE(std::abs(violation), tolerance * scale)
        << what << " violated by " << violation << " (scale " << scale << ")";
  }

  // Every expected field must have been compared: a field the driver does not know is an error
  // of the file or of the driver, never silently skipped.
  void all_checked() const {
    for (const auto& item : expected_.items())
      EXPECT_TRUE(checked_.count(item.key()) == 1)
          << "expected field '" << item.key() << "' is not checked by the driver";
  }

 private:
  void compare(const std::string& what, double actual, double expected) const {
    EXPECT_LE(std::abs(actual - expected), tolerance_ * std::max(std::abs(expected), scale_))
        << what << ": got " << actual << ", expected " << expected << " (difference "
        << actual - expected << ", tolerance " << tolerance_ << ")";
  }

  const json& expected_;
  double tolerance_, scale_;
  std::set<std::string> checked_;
};

template <std::size_t N>
double magnitude(const std::array<double, N>& a) {
  return std::sqrt(norm2(a));
}
double magnitude(double a) {
  return std::abs(a);
}

// Linear momentum of two bodies: the violation |p' - p| and the scale sum m |v| (before and
// after).
template <int D>
void check_momentum(double mi, double mj, const Vec<D>& vi0, const Vec<D>& vj0, const Vec<D>& vi,
                    const Vec<D>& vj) {
  const Vec<D> dp = (mi * vi + mj * vj) - (mi * vi0 + mj * vj0);
  const double scale =
      mi * (magnitude(vi0) + magnitude(vi)) + mj * (magnitude(vj0) + magnitude(vj));
  Checker::conserved("momentum", magnitude(dp), scale, kMomentumTolerance);
}

// ---------------------------------------------------------------------------------------------
// Hard spheres: HardSphere::contact_time, then the elastic impulse at contact.

template <int D>
void run_hard_sphere(const json& in, Checker& check) {
  const double mi = in.at("mass_i"), mj = in.at("mass_j");
  const double sigma = in.at("radius_i").get<double>() + in.at("radius_j").get<double>();
  Vec<D> ri = vec_of<D>(in.at("r_i")), rj = vec_of<D>(in.at("r_j"));
  const Vec<D> vi0 = vec_of<D>(in.at("v_i")), vj0 = vec_of<D>(in.at("v_j"));
  Vec<D> vi = vi0, vj = vj0;
  const Vec<D> g = vi - vj;
  const Vec<D> r0 = ri - rj;
  const double t = HardSphere::contact_time(norm2(r0), dot(r0, g), norm2(g), sigma);
  check.time("contact_time", t);
  Vec<D> impulse{};
  if (t < kNever) {
    ri = ri + t * vi, rj = rj + t * vj;
    const Vec<D> r = ri - rj;
    const double mu = mi * mj / (mi + mj);
    impulse = HardSphere::impulse_factor(dot(g, r), norm2(r), mu) * r;
    vi = vi + (1.0 / mi) * impulse;
    vj = vj - (1.0 / mj) * impulse;
  }
  check.vector("v_i", vi);
  check.vector("v_j", vj);
  check.vector("impulse", impulse);
  check.scalar("dissipated", 0.0);
  check_momentum<D>(mi, mj, vi0, vj0, vi, vj);
  const double k0 = 0.5 * (mi * norm2(vi0) + mj * norm2(vj0));
  const double k1 = 0.5 * (mi * norm2(vi) + mj * norm2(vj));
  Checker::conserved("kinetic energy", k1 - k0, k0 + k1, kEnergyTolerance);
}

// ---------------------------------------------------------------------------------------------
// Granular contacts: resolve_contact and resolve_wall_contact with spins.

template <int D>
void check_contact_result(Checker& check, const ContactResult<D>& r) {
  check.vector("impulse", r.impulse);
  check.scalar("normal_impulse", r.normal_impulse);
  check.vector("tangential_impulse", r.tangential_impulse);
  check.scalar("impact_speed", r.impact_speed);
  check.scalar("restitution", r.restitution);
  check.scalar("translational_energy_change", r.translational_energy_change);
  check.scalar("rotational_energy_change", r.rotational_energy_change);
  check.scalar("dissipated", r.dissipated);
  check.flag("slid", r.slid);
  check.flag("made_elastic", r.made_elastic);
}

// A body at x (relative to the contact point) with mass m and moment of inertia I.
template <int D>
struct Body {
  Vec<D> x{}, v{};
  Spin<D> w{};
  double m = 1.0, inertia = 1.0;
  double translational() const { return 0.5 * m * norm2(v); }
  double rotational() const { return 0.5 * inertia * spin_dot(w, w); }
  // Angular momentum about the contact point, m x cross v + I w, and its scale.
  Spin<D> angular_momentum() const { return m * cross(x, v) + inertia * w; }
  double angular_scale() const { return m * magnitude(x) * magnitude(v) + inertia * magnitude(w); }
};

template <int D>
Body<D> body_of(const json& in, const std::string& suffix, double sign, const Vec<D>& n) {
  Body<D> b;
  const double radius = in.at("radius" + suffix);
  b.m = in.at("mass" + suffix);
  b.inertia = in.at("inertia_factor" + suffix).get<double>() * b.m * radius * radius;
  b.x = (sign * radius) * n;
  b.v = vec_of<D>(in.at(suffix.empty() ? "v" : "v" + suffix));
  b.w = spin_of<D>(in.at(suffix.empty() ? "w" : "w" + suffix));
  return b;
}

template <int D>
void run_granular_pair(const json& in, Checker& check) {
  const ContactModel model = contact_model_of(in.at("law"));
  ContactInput<D> ci;
  ci.normal = vec_of<D>(in.at("normal"));
  ci.mass_i = in.at("mass_i"), ci.mass_j = in.at("mass_j");
  ci.radius_i = in.at("radius_i"), ci.radius_j = in.at("radius_j");
  ci.inertia_factor_i = in.at("inertia_factor_i"), ci.inertia_factor_j = in.at("inertia_factor_j");
  ci.force_elastic = in.at("force_elastic");
  const Body<D> i0 = body_of<D>(in, "_i", 1.0, ci.normal);
  const Body<D> j0 = body_of<D>(in, "_j", -1.0, ci.normal);
  Body<D> i = i0, j = j0;
  const ContactResult<D> r = resolve_contact<D>(model, ci, i.v, j.v, i.w, j.w);
  check.vector("v_i", i.v);
  check.vector("v_j", j.v);
  check.spin("w_i", i.w);
  check.spin("w_j", j.w);
  check_contact_result<D>(check, r);

  check_momentum<D>(i.m, j.m, i0.v, j0.v, i.v, j.v);
  const double tr = i.translational() + j.translational() - i0.translational() - j0.translational();
  const double rot = i.rotational() + j.rotational() - i0.rotational() - j0.rotational();
  const double scale = i.translational() + j.translational() + i0.translational() +
                       j0.translational() + i.rotational() + j.rotational() + i0.rotational() +
                       j0.rotational();
  Checker::conserved("energy balance: kinetic change + dissipated", tr + rot + r.dissipated, scale,
                     kEnergyTolerance);
  Checker::conserved("translational change reported vs direct", r.translational_energy_change - tr,
                     scale, kEnergyTolerance);
  Checker::conserved("rotational change reported vs direct", r.rotational_energy_change - rot,
                     scale, kEnergyTolerance);
  const Spin<D> dl = (i.angular_momentum() + j.angular_momentum()) -
                     (i0.angular_momentum() + j0.angular_momentum());
  Checker::conserved(
      "angular momentum about the contact point", magnitude(dl),
      i.angular_scale() + j.angular_scale() + i0.angular_scale() + j0.angular_scale(),
      kMomentumTolerance);
}

template <int D>
void run_granular_wall(const json& in, Checker& check) {
  const ContactModel model = contact_model_of(in.at("law"));
  WallContactInput<D> wi;
  wi.normal = vec_of<D>(in.at("normal"));
  wi.wall_velocity = vec_of<D>(in.at("wall_velocity"));
  wi.mass = in.at("mass");
  wi.radius = in.at("radius");
  wi.inertia_factor = in.at("inertia_factor");
  wi.force_elastic = in.at("force_elastic");
  const Body<D> b0 = body_of<D>(in, "", 1.0, wi.normal);
  Body<D> b = b0;
  const ContactResult<D> r = resolve_wall_contact<D>(model, wi, b.v, b.w);
  check.vector("v", b.v);
  check.spin("w", b.w);
  check_contact_result<D>(check, r);

  const double change = b.translational() + b.rotational() - b0.translational() - b0.rotational();
  const double scale = b.translational() + b.rotational() + b0.translational() + b0.rotational();
  check.scalar("wall_work", change + r.dissipated);
  Checker::conserved("energy balance: kinetic change + dissipated - J.u",
                     change + r.dissipated - dot(r.impulse, wi.wall_velocity), scale,
                     kEnergyTolerance);
  // The wall's impulse acts at the contact point: no torque about it.
  Checker::conserved("angular momentum about the contact point",
                     magnitude(b.angular_momentum() - b0.angular_momentum()),
                     b.angular_scale() + b0.angular_scale(), kMomentumTolerance);
}

// ---------------------------------------------------------------------------------------------
// Step events: step_event, or dissipative_step_event with a dashpot.

template <int D>
void run_step_event(const json& in, Checker& check) {
  const double mi = in.at("mass_i"), mj = in.at("mass_j");
  const double mu = mi * mj / (mi + mj);
  const double delta_u = in.at("delta_u");
  const Vec<D> n = vec_of<D>(in.at("normal"));
  const Vec<D> vi0 = vec_of<D>(in.at("v_i")), vj0 = vec_of<D>(in.at("v_j"));
  const double v_n = dot(vi0 - vj0, n);
  bool crosses = false;
  double impulse = 0.0, dissipated = 0.0;
  if (in.contains("dashpot")) {
    const json& d = in.at("dashpot");
    const DissipativeStepOutcome out = dissipative_step_event(mu, v_n, delta_u, d.at("damping"),
                                                              d.at("width"), d.at("force_zero"));
    crosses = out.crosses, impulse = out.impulse, dissipated = out.dissipated;
  } else {
    const StepOutcome out = step_event(mu, v_n, delta_u);
    crosses = out.crosses, impulse = out.impulse;
  }
  const Vec<D> vi = vi0 + (impulse / mi) * n, vj = vj0 - (impulse / mj) * n;
  check.flag("crosses", crosses);
  check.scalar("impulse", impulse);
  check.vector("v_i", vi);
  check.vector("v_j", vj);
  check.scalar("dissipated", dissipated);

  check_momentum<D>(mi, mj, vi0, vj0, vi, vj);
  const double k0 = 0.5 * (mi * norm2(vi0) + mj * norm2(vj0));
  const double k1 = 0.5 * (mi * norm2(vi) + mj * norm2(vj));
  Checker::conserved("energy balance: kinetic change + dU (if crossed) + dissipated",
                     k1 - k0 + (crosses ? delta_u : 0.0) + dissipated, k0 + k1 + std::abs(delta_u),
                     kEnergyTolerance);
}

// ---------------------------------------------------------------------------------------------
// Soft spheres: soft_collision (the collision map) from first contact to the force-zero end.

void run_soft_collision(const json& in, Checker& check) {
  if (in.at("dimension").get<int>() != 3)
    throw std::runtime_error("soft collisions are three-dimensional");
  const std::string model = in.at("model");
  SoftContactLaw law;
  if (model == "linear_dashpot") {
    law = SoftContactLaw::linear_dashpot(in.at("k"), in.at("gamma"));
  } else if (model == "viscoelastic_hertz") {
    law = SoftContactLaw::viscoelastic_hertz(in.at("rho"), in.at("A"));
  } else {
    throw std::runtime_error("unknown soft contact model '" + model + "'");
  }
  SoftPair pair;
  pair.m_i = in.at("mass_i"), pair.m_j = in.at("mass_j");
  pair.radius_i = in.at("radius_i"), pair.radius_j = in.at("radius_j");
  PairState s0;
  s0.r_i = vec_of<3>(in.at("r_i")), s0.r_j = vec_of<3>(in.at("r_j"));
  s0.v_i = vec_of<3>(in.at("v_i")), s0.v_j = vec_of<3>(in.at("v_j"));
  const SoftCollision out = soft_collision(law, pair, s0);
  const PairState& s = out.state;
  const double mi = pair.m_i, mj = pair.m_j, mu = mi * mj / (mi + mj);
  const double k0 = 0.5 * (mi * norm2(s0.v_i) + mj * norm2(s0.v_j));
  const double k1 = 0.5 * (mi * norm2(s.v_i) + mj * norm2(s.v_j));
  check.scalar("eps_rdot", out.map.eps_rdot);
  check.scalar("eps_r", out.map.eps_r);
  check.scalar("contact_time", out.contact_time);
  check.vector("v_i", s.v_i);
  check.vector("v_j", s.v_j);
  check.vector("r_i", s.r_i);
  check.vector("r_j", s.r_j);
  check.scalar("dissipated", k0 - k1);
  if (check.expects("naive_restitution"))  // the dashpot's naive end, for underdamped cases
    check.scalar("naive_restitution",
                 dashpot_head_on_naive_reduced(law.damping / (2.0 * std::sqrt(law.stiffness * mu)))
                     .restitution);

  check_momentum<3>(mi, mj, s0.v_i, s0.v_j, s.v_i, s.v_j);
  // The map's energy loss: (1/2) mu [v_n^2 (1 - eps_rdot^2) + v_t^2 (1 - eps_r^-2)].
  const Vec<3> r0 = s0.r_i - s0.r_j, g0 = s0.v_i - s0.v_j;
  const double v_n = -dot(g0, r0) / magnitude(r0);
  const double v_t2 = std::max(0.0, norm2(g0) - v_n * v_n);
  const double eps_r2 = out.map.eps_r * out.map.eps_r;
  const double loss =
      0.5 * mu *
      (v_n * v_n * (1.0 - out.map.eps_rdot * out.map.eps_rdot) + v_t2 * (1.0 - 1.0 / eps_r2));
  Checker::conserved("energy balance: kinetic change + the map's loss", k1 - k0 + loss, k0 + k1,
                     kEnergyTolerance);
  // The centre of mass moves on uniformly through the contact.
  const double M = mi + mj;
  const Vec<3> R0 = (mi / M) * s0.r_i + (mj / M) * s0.r_j;
  const Vec<3> V = (mi / M) * s0.v_i + (mj / M) * s0.v_j;
  const Vec<3> R1 = (mi / M) * s.r_i + (mj / M) * s.r_j;
  Checker::conserved("uniform motion of the centre of mass",
                     magnitude(R1 - (R0 + out.contact_time * V)),
                     magnitude(R0) + pair.radius_i + pair.radius_j, kMomentumTolerance);
}

// ---------------------------------------------------------------------------------------------
// Dispatch on the file's `interaction`.

using Runner = std::function<void(const json&, Checker&)>;

template <template <int> class Run>
Runner by_dimension() {
  return [](const json& in, Checker& check) {
    const int d = in.at("dimension");
    if (d == 2) {
      Run<2>{}(in, check);
    } else if (d == 3) {
      Run<3>{}(in, check);
    } else {
      throw std::runtime_error("dimension must be 2 or 3, got " + std::to_string(d));
    }
  };
}

template <int D>
struct HardSphereRun {
  void operator()(const json& in, Checker& c) const { run_hard_sphere<D>(in, c); }
};
template <int D>
struct GranularPairRun {
  void operator()(const json& in, Checker& c) const { run_granular_pair<D>(in, c); }
};
template <int D>
struct GranularWallRun {
  void operator()(const json& in, Checker& c) const { run_granular_wall<D>(in, c); }
};
template <int D>
struct StepEventRun {
  void operator()(const json& in, Checker& c) const { run_step_event<D>(in, c); }
};

const std::map<std::string, Runner>& interactions() {
  static const std::map<std::string, Runner> kInteractions = {
      {"hard_sphere", by_dimension<HardSphereRun>()},
      {"granular_contact", by_dimension<GranularPairRun>()},
      {"granular_wall_contact", by_dimension<GranularWallRun>()},
      {"step_event", by_dimension<StepEventRun>()},
      {"soft_collision", run_soft_collision},
  };
  return kInteractions;
}

// ---------------------------------------------------------------------------------------------
// The tests: one per file.

class ReferenceValues : public testing::TestWithParam<std::string> {};

TEST_P(ReferenceValues, EveryCaseMatchesAndConserves) {
  const std::string stem = GetParam();
  const json file = read_file(stem);
  const std::string interaction = file.at("interaction");
  const auto runner = interactions().find(interaction);
  ASSERT_NE(runner, interactions().end())
      << stem << ".json: no dispatch branch for interaction '" << interaction << "'";
  const json& cases = file.at("cases");
  ASSERT_FALSE(cases.empty()) << stem << ".json has no cases";
  for (const json& c : cases) {
    const std::string name = c.at("name");
    SCOPED_TRACE(stem + ".json, case " + name + " (" + c.value("source", "") + ")");
    Checker check(c);
    try {
      runner->second(c.at("input"), check);
    } catch (const std::exception& e) {
      ADD_FAILURE() << "threw: " << e.what();
      continue;
    }
    check.all_checked();
  }
}

std::string test_name(const testing::TestParamInfo<std::string>& info) {
  std::string name = info.param;
  for (char& ch : name)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(Reference, ReferenceValues, testing::ValuesIn(reference_files()),
                         test_name);

// The directory holds a file for every interaction the driver knows, and case names are unique
// within a file (a failure names its case).
TEST(ReferenceDirectory, EveryInteractionHasAFileAndNamesAreUnique) {
  std::set<std::string> seen;
  for (const std::string& stem : reference_files()) {
    const json file = read_file(stem);
    seen.insert(file.at("interaction").get<std::string>());
    std::set<std::string> names;
    for (const json& c : file.at("cases"))
      EXPECT_TRUE(names.insert(c.at("name").get<std::string>()).second)
          << stem << ".json: case name '" << c.at("name") << "' repeats";
  }
  for (const auto& [interaction, runner] : interactions())
    EXPECT_TRUE(seen.count(interaction) == 1) << "no reference file for '" << interaction << "'";
}

}  // namespace
}  // namespace kairos

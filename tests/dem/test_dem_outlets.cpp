// Outlets in the DEM (boundary.outlet; boundaries/outlets.hpp, boundaries/outlet_placement.hpp):
// a particle whose centre has crossed the outlet's plane at the end of a step is put back at a
// free place of the insertion region, as the event engine does. Disks in free fall pass at the
// step the exact parabola says (velocity Verlet is exact under a constant force) and the energy
// they take out closes the budget to round-off; a draining frictional silo never puts a disk
// where it overlaps, keeps every centre above the outlet, closes its budget to the DEM's O(dt^2)
// with the outlet's share (and misses it by far without); a resumed silo continues bit for bit;
// a start beyond the outlet and a region outside the walls are refused by name.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "dem/dem_integrator.hpp"
#include "interactions/soft_contact.hpp"

namespace kairos {
namespace {

constexpr int D = 2;
constexpr double kOutletLevel = 3.5;

// A 2D silo in the DEM: box 16 x 30 with walls on every face (the DEM has no open faces), a floor
// at y = 4 with an orifice `width` wide around x = 8 (two strips), an outlet a radius below it
// that puts disks back at rest in [0.6, 15.4] x [20, 29]; linear spring-dashpot disks
// (k = 10^5, e = 0.8) under g = -1, with Coulomb friction mu = 0.5 when `rough`.
Environment<D> silo(double width, bool rough) {
  const double k = 1e5;
  const SoftContactLaw pair =
      SoftContactLaw::linear_dashpot(k, dashpot_damping_for_restitution(0.5, k, 0.8));
  const SoftContactLaw wall =
      SoftContactLaw::linear_dashpot(k, dashpot_damping_for_restitution(1.0, k, 0.8));
  Environment<D> env;
  env.species = 1;
  env.soft = {pair};
  env.soft_wall = {wall};
  if (rough) {
    env.soft_friction = {SoftFriction{0.5, 2.0 / 7.0, 0.5}};
    env.soft_wall_friction = env.soft_friction;
  }
  env.gravity = {0.0, -1.0};
  for (Face<D>& f : env.faces) f.kind = FaceKind::kWall;
  for (const auto& [lo, hi] :
       {std::pair{-kNever, 8.0 - 0.5 * width}, std::pair{8.0 + 0.5 * width, kNever}}) {
    PlaneWall<D> p;
    p.normal = {0.0, 1.0};
    p.offset = 4.0;
    p.span_axis = 0;
    p.span_min = lo;
    p.span_max = hi;
    surface_specs<PlaneWalls<D>>(env).push_back(p);
  }
  Outlet<D> o;
  o.normal = {0.0, 1.0};
  o.offset = kOutletLevel;
  o.insert_lower = {0.6, 20.0};
  o.insert_upper = {15.4, 29.0};
  o.seed = 4;
  env.outlets = {o};
  return env;
}

ParticleSystem<D> disks(const std::vector<Vec<D>>& at, const std::vector<Vec<D>>& v) {
  ParticleSystem<D> s;
  s.box = {16.0, 30.0};
  s.periodic = {false, false};
  for (std::size_t i = 0; i < at.size(); ++i) {
    s.kinematics.push_back({at[i], v[i], 0.0, 0.5});
    s.mass.push_back(1.0);
  }
  return s;
}

ParticleSystem<D> grains_above_the_floor(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec<D>> at, v;
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j) {
      at.push_back({1.0 + 1.25 * i, 6.0 + 1.25 * j});
      v.push_back({u(rng), u(rng)});
    }
  return disks(at, v);
}

// Kinetic + rotational + elastic + gravitational energy, plus what the damping took and the
// outlet took out, less the walls' work: constant to O(dt^2) (to round-off without contacts).
double budget(const DemIntegrator<D>& dem, bool with_outlet = true) {
  return dem.kinetic_energy() + dem.rotational_energy() + dem.potential_energy() +
         dem.field_energy() + dem.dissipated_energy() + dem.dissipated_at_walls() -
         dem.work_by_walls() + (with_outlet ? dem.outlet_energy() : 0.0);
}

// Disks dropped from rest over the orifice, far apart, never touch anything before they pass:
// the count of passes after each step is the number of parabolas y0 - t^2 / 2 below the
// outlet by then, and each pass took out m g (y0 - y_put_back) exactly.
TEST(DemOutlets, FreeFallingDisksPassAtTheStepTheParabolaSays) {
  std::vector<Vec<D>> at, v;
  for (int i = 0; i < 5; ++i) {
    at.push_back({6.5 + 0.75 * i, 5.0 + 3.1 * i});
    v.push_back({0.0, 0.0});
  }
  DemIntegrator<D> dem(disks(at, v), silo(5.0, false));
  const double dt = dem.dt();
  const double e0 = budget(dem);
  std::vector<double> heights;  // every drop height so far; a pass puts the disk back higher up
  for (const Vec<D>& x : at) heights.push_back(x[1]);
  std::size_t passed = 0;
  // Until t = 6: after the last first crossing (t = 5.27), before any second one (t > 7.4: put
  // back at y >= 20) and before a disk put back reaches the floor (t > 7.3).
  const long steps = std::lround(6.0 / dt);
  for (long n = 1; n <= steps; ++n) {
    dem.step(1);
    const double t = static_cast<double>(n) * dt;
    std::size_t expected = 0;
    for (std::size_t i = 0; i < at.size(); ++i) {
      const double crossing = std::sqrt(2.0 * (at[i][1] - kOutletLevel));
      ASSERT_GT(std::abs(crossing - t), 1e-9) << "a crossing on a step: the test is ambiguous";
      expected += crossing < t ? 1 : 0;
    }
    ASSERT_EQ(dem.outlet_passes(), expected) << "after step " << n;
    passed = expected;
  }
  ASSERT_EQ(passed, at.size());  // all passed once, none twice yet (put back at y >= 20)
  EXPECT_EQ(dem.outlet_mass(), static_cast<double>(passed));
  double taken = 0.0;  // m g (y0 - h) for each disk, h the height it was put back at
  for (std::size_t i = 0; i < at.size(); ++i) {
    const Vec<D> x = dem.position(i), u = dem.velocity(i);
    EXPECT_GE(x[0], 0.6);
    EXPECT_LE(x[0], 15.4);
    EXPECT_LE(x[1], 29.0);
    // Put back at rest at some height h, it has fallen since: y + v^2 / 2 = h.
    const double h = x[1] + 0.5 * norm2(u);
    EXPECT_GE(h, 20.0 - 1e-9);
    taken += at[i][1] - h;
  }
  EXPECT_NEAR(dem.outlet_energy(), taken, 1e-11 * std::abs(taken));
  // Round-off of 44 000 steps of x += dt u (1e-16 of x each).
  EXPECT_NEAR(budget(dem), e0, 1e-11 * std::abs(e0));
  EXPECT_EQ(dem.contact_count(), 0u);
  EXPECT_EQ(dem.wall_collisions(), 0u);
}

// The budget's relative error after `steps` steps of the silo (with or without its outlet: the
// disks then fall onto the box's floor at y = 0), and the largest overlap seen; no centre ever
// below the outlet.
struct SiloRun {
  double error = 0.0, error_without_outlet_share = 0.0, largest_overlap = 0.0;
  std::uint64_t passes = 0;
  double time = 0.0;
};

SiloRun run_silo(bool with_outlet, int chunks) {
  Environment<D> env = silo(5.0, true);
  if (!with_outlet) env.outlets.clear();
  DemIntegrator<D> dem(grains_above_the_floor(1), env);
  const double e0 = budget(dem);
  SiloRun r;
  for (int chunk = 0; chunk < chunks; ++chunk) {
    dem.step(250);
    for (std::size_t i = 0; i < dem.size(); ++i) {
      const Vec<D> xi = dem.position(i);
      if (with_outlet) {
        EXPECT_GT(xi[1], kOutletLevel) << "a centre below the outlet, particle " << i;
      }
      for (std::size_t j = i + 1; j < dem.size(); ++j)
        r.largest_overlap =
            std::max(r.largest_overlap, 1.0 - std::sqrt(norm2(xi - dem.position(j))));
    }
  }
  const double scale = std::abs(e0) + dem.dissipated_energy() + dem.dissipated_at_walls() +
                       std::abs(dem.outlet_energy());
  r.error = std::abs(budget(dem) - e0) / scale;
  r.error_without_outlet_share = std::abs(budget(dem, false) - e0) / scale;
  r.passes = dem.outlet_passes();
  r.time = dem.time();
  return r;
}

// Rough, inelastic disks drain through a five-diameter orifice and come back at the top. The
// budget closes as well as the DEM's own O(dt^2) allows: as in the same silo without its
// outlet, where the disks pile up on the box's floor instead.
TEST(DemOutlets, ARoughSiloDrainsWithoutOverlapsAndClosesItsBudget) {
  const SiloRun open = run_silo(true, 600), closed = run_silo(false, 600);
  EXPECT_GT(open.passes, 40u) << "in " << open.time << " time units";
  // A soft contact overlaps by ~ v sqrt(m / k): 1 % of a diameter at the orifice's speeds; a
  // disk put back onto another would overlap by up to a radius.
  EXPECT_LT(open.largest_overlap, 0.03);
  EXPECT_LT(open.error, 3.0 * closed.error)
      << "with the outlet " << open.error << ", without " << closed.error;
  // The outlet's share is what closes it: without, it is off by the passes' energy.
  EXPECT_GT(open.error_without_outlet_share, 30.0 * open.error);
}

TEST(DemOutlets, AResumedSiloContinuesBitForBit) {
  const Environment<D> env = silo(5.0, true);
  DemIntegrator<D> a(grains_above_the_floor(2), env);
  a.step(60000);
  ASSERT_GT(a.outlet_passes(), 5u);
  ParticleSystem<D> state = a.export_state();
  state.dem = a.checkpoint();
  DemIntegrator<D> b(state, env);
  EXPECT_EQ(b.outlet_passes(), a.outlet_passes());
  const std::uint64_t passes = a.outlet_passes();
  a.step(20000);
  b.step(20000);
  EXPECT_GT(a.outlet_passes(), passes);
  EXPECT_EQ(b.outlet_passes(), a.outlet_passes());
  EXPECT_EQ(b.outlet_energy(), a.outlet_energy());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(b.position(i), a.position(i)) << "particle " << i;
    ASSERT_EQ(b.velocity(i), a.velocity(i)) << "particle " << i;
  }
}

// An outlet laid across a bed: six disks stacked on the floor, the outlet's plane a hair below
// the bottom disk's centre (0.49999 above the floor). The column's weight presses the bottom
// disk 6e-5 into the floor, its centre beyond the plane while it touches the floor and the disk
// above: it never passes, and the summary's waiting count says so (the event engine, whose
// hard disks do not sink, would never see it beyond the plane).
TEST(DemOutlets, ADiskBeyondThePlaneThatStillTouchesWaits) {
  std::vector<Vec<D>> at, v;
  for (int j = 0; j < 6; ++j) {
    at.push_back({8.0, 4.5 + j});
    v.push_back({0.0, 0.0});
  }
  Environment<D> env = silo(5.0, false);
  surface_specs<PlaneWalls<D>>(env).clear();
  PlaneWall<D> floor;
  floor.normal = {0.0, 1.0};
  floor.offset = 4.0;
  surface_specs<PlaneWalls<D>>(env).push_back(floor);
  env.outlets[0].offset = 4.49999;
  DemIntegrator<D> dem(disks(at, v), env);
  dem.step(20000);
  EXPECT_EQ(dem.outlet_passes(), 0u);
  EXPECT_EQ(dem.outlet_waiting(), 1u);
  EXPECT_LT(dem.position(0)[1], 4.49999);
}

TEST(DemOutlets, AStartBeyondTheOutletIsRefusedNamingTheParticle) {
  try {
    DemIntegrator<D> dem(disks({{8.0, 10.0}, {8.0, 3.0}}, {{0.0, 0.0}, {0.0, 0.0}}),
                         silo(5.0, false));
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("boundary.outlet"), std::string::npos) << what;
    EXPECT_NE(what.find("particle 1"), std::string::npos) << what;
  }
}

TEST(DemOutlets, AnInsertionRegionOutsideTheWallsIsRefused) {
  Environment<D> env = silo(5.0, false);
  env.outlets[0].insert_lower = {0.2, 25.0};  // a point within a radius of the wall x = 0
  env.outlets[0].insert_upper = {0.2, 25.0};
  try {
    DemIntegrator<D> dem(disks({{8.0, 10.0}}, {{0.0, 0.0}}), env);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("boundary.outlet: no place in the insertion region"), std::string::npos)
        << what;
  }
}

}  // namespace
}  // namespace kairos

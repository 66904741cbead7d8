// Compression by growth (run/compression.hpp; docs/physics.md#growing-spheres): to a target
// packing fraction exactly, with no overlap; to jamming in 3D (one size) and 2D (1:1.4 disks),
// the jamming densities in the published ranges; the pressure on the way against the
// equation of state; refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "../release_suite_only.hpp"
#include "analysis/contact_network.hpp"
#include "core/error.hpp"
#include "core/periodic.hpp"
#include "engine/event_engine.hpp"
#include "init/initial_state.hpp"
#include "io/config.hpp"
#include "run/compression.hpp"
#include "run/start_state.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

template <int D>
ParticleSystem<D> random_start(std::uint64_t n, double eta, std::uint64_t seed, double big = 0.0) {
  SystemConfig c;
  c.dimension = D;
  c.particles = n;
  c.packing_fraction = eta;
  c.lattice = "random";
  c.seed = seed;
  if (big > 0.0) {
    c.species = {SpeciesConfig{.name = "A", .diameter = 1.0, .fraction = 0.5},
                 SpeciesConfig{.name = "B", .diameter = big, .fraction = 0.5}};
  } else {
    c.species = {SpeciesConfig{}};
  }
  std::mt19937_64 rng(seed);
  return to_particle_system<D>(make_initial_state<D>(c, rng));
}

template <int D>
Configuration<D> configuration_of(const ParticleSystem<D>& s) {
  Configuration<D> c;
  c.box = s.box;
  c.periodic.fill(true);
  for (std::size_t i = 0; i < s.size(); ++i) {
    c.position.push_back(s.kinematics[i].pos);
    c.species.push_back(s.species[i]);
    c.radius.push_back(s.kinematics[i].radius);
  }
  return c;
}

// The largest overlap of any pair, by brute force over nearest images.
template <int D>
double max_overlap(const ParticleSystem<D>& s) {
  double worst = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i)
    for (std::size_t j = i + 1; j < s.size(); ++j)
      worst = std::max(worst,
                       pair_overlap<D>(s.box, s.kinematics[i].pos, s.kinematics[j].pos,
                                       2.0 * s.kinematics[i].radius, 2.0 * s.kinematics[j].radius));
  return worst;
}

TEST(Compression, ReachesATargetPackingFractionExactly) {
  auto s = random_start<3>(500, 0.3, 3);
  CompressionSettings c;
  c.growth_rate = 0.01;
  c.target_packing_fraction = 0.58;
  const CompressionResult r = compress(s, c);
  EXPECT_EQ(r.stop_reason, "packing_fraction");
  EXPECT_NEAR(state_packing_fraction(s), 0.58, 1e-12);
  EXPECT_NEAR(r.packing_fraction, 0.58, 1e-12);
  // The particles outgrew the first engine's cells: every interval, across the rebuilds, is
  // as long as asked, and the clock and the packing fraction only advance.
  EXPECT_GE(r.rebuilds, 1u);
  const std::uint64_t per_interval = 500 * 10 / 2;
  for (std::size_t k = 1; k < r.rows.size(); ++k) {
    EXPECT_EQ(r.rows[k].collisions - r.rows[k - 1].collisions, per_interval) << "row " << k;
    EXPECT_GT(r.rows[k].time, r.rows[k - 1].time) << "row " << k;
    EXPECT_GT(r.rows[k].packing_fraction, r.rows[k - 1].packing_fraction) << "row " << k;
    EXPECT_GT(r.rows[k].pressure, 0.8 * r.rows[k - 1].pressure) << "row " << k;
  }
  EXPECT_NEAR(r.time, ((std::cbrt(0.58 / 0.3) - 1.0) / 0.01), 1e-6);
  EXPECT_LT(max_overlap(s), 1e-12);
  EXPECT_EQ(s.time, 0.0);
  EXPECT_GT(r.rescalings, 10u);
  // Velocities at the set temperature, by the run's definition kT = 2K / (D (N - 1)) (the
  // centre of mass does not move).
  double k2 = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) k2 += s.mass[i] * norm2(s.kinematics[i].vel);
  EXPECT_NEAR(k2 / (3.0 * 499.0), 1.0, 1e-12);
}

// The reduced pressure of the hard-sphere fluid (Kolafa, Labik and Malijevsky, PCCP 6, 2335
// (2004), coefficients as in Pieprzyk et al., PCCP 21, 6886 (2019)); valid below eta ~ 0.55.
double klm_pressure(double eta) {
  const double x = eta / (1.0 - eta);
  const double c[] = {1,          4,          6,           2.3647684, -0.8698551,  1.1062803,
                      -1.1014221, 0.66605866, -0.03633431, 0,         -0.20965164, 0,
                      0,          0,          0.10555569,  0,         0,           0,
                      0,          0,          0,           0,         -0.00872380};
  double z = 0.0, p = 1.0;
  for (double k : c) {
    z += k * p;
    p *= x;
  }
  return z;
}

TEST(Compression, GrowsAWideMixtureOnTwoCellLevels) {
  // Diameters 1 and 6, 1.5 % big ones: the engines of the protocol keep the two sizes on two
  // cell levels (engine/cell_neighbourhood.hpp) across their rebuilds; the target is reached
  // exactly, with no overlap (brute force), the size ratio kept.
  SystemConfig c;
  c.dimension = 3;
  c.particles = 2000;
  c.packing_fraction = 0.3;
  c.lattice = "random";
  c.seed = 9;
  c.species = {SpeciesConfig{.name = "A", .diameter = 1.0, .fraction = 0.985},
               SpeciesConfig{.name = "B", .diameter = 6.0, .mass = 216.0, .fraction = 0.015}};
  std::mt19937_64 rng(9);
  auto s = to_particle_system<3>(make_initial_state<3>(c, rng));
  {
    EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict);
    ASSERT_TRUE(engine.two_level_cells());
  }
  CompressionSettings settings;
  settings.growth_rate = 0.02;
  settings.target_packing_fraction = 0.5;
  const CompressionResult r = compress(s, settings);
  EXPECT_EQ(r.stop_reason, "packing_fraction");
  EXPECT_NEAR(state_packing_fraction(s), 0.5, 1e-12);
  EXPECT_GE(r.rebuilds, 1u);
  EXPECT_LT(max_overlap(s), 1e-12);
  double small = kNever, big = 0.0;
  for (const Kinematics<3>& k : s.kinematics) {
    small = std::min(small, k.radius);
    big = std::max(big, k.radius);
  }
  EXPECT_DOUBLE_EQ(big / small, 6.0);
  EventEngine<3, CalendarQueue> engine(s, StartMode::kPredict);
  EXPECT_TRUE(engine.two_level_cells());
}

TEST(Compression, SlowGrowthFollowsTheEquationOfState) {
  KAIROS_RELEASE_SUITE_ONLY();
  auto s = random_start<3>(1000, 0.3, 6);
  CompressionSettings c;
  c.growth_rate = 1e-3;
  c.thermostat_interval = 1.0;
  c.target_packing_fraction = 0.47;
  const CompressionResult r = compress(s, c);
  // Rows averaged in windows of packing fraction: Z against the equation of state, within the
  // scatter of the window (2 %) and the lag of a finite growth rate (Z a little above).
  // The collision rate against the pressure: with Maxwellian velocities the colliding pairs'
  // normal speed averages sqrt(pi kT / m) (flux-weighted), so Z - 1 = sqrt(pi) w / (2 D), w the
  // collisions per particle per unit time in units of sqrt(kT/m)/sigma (docs/physics.md).
  for (const double eta : {0.35, 0.40, 0.45}) {
    double sum = 0.0, rate = 0.0;
    int rows = 0;
    for (const CompressionRow& row : r.rows) {
      if (std::abs(row.packing_fraction - eta) > 0.005) continue;
      sum += row.pressure;
      rate += row.collision_rate;
      ++rows;
    }
    ASSERT_GT(rows, 20) << eta;
    const double z = sum / rows, ref = klm_pressure(eta) * (1.0 + 0.0);
    EXPECT_NEAR(z / ref, 1.0, 0.03) << "eta " << eta << ": Z " << z << " vs " << ref;
    const double from_rate = 1.0 + std::sqrt(M_PI) * (rate / rows) / 6.0;
    EXPECT_NEAR(from_rate / z, 1.0, 0.01) << "eta " << eta;
    std::printf("eta %.2f Z %.4f KLM %.4f ratio %.4f rows %d; from the collision rate %.4f\n", eta,
                z, ref, z / ref, rows, from_rate);
  }
}

// Jammed by the collision rate (compress.jammed_collision_rate): it diverges with the pressure,
// w = 2 D (Z - 1) / sqrt(pi) up to the departure from a Maxwellian near jamming.
TEST(Compression, JammedByTheCollisionRate) {
  KAIROS_RELEASE_SUITE_ONLY();
  auto s = random_start<3>(300, 0.3, 33);
  CompressionSettings c;
  c.jammed_collision_rate = 1e6;
  const CompressionResult r = compress(s, c);
  ASSERT_EQ(r.stop_reason, "collision_rate");
  ASSERT_GE(r.rows.size(), 2u);
  EXPECT_GE(r.rows.back().collision_rate, 1e6);
  EXPECT_LT(r.rows[r.rows.size() - 2].collision_rate, 1e6);
  EXPECT_EQ(r.collision_rate, r.rows.back().collision_rate);
  EXPECT_NEAR(r.collision_rate / (6.0 * (r.pressure - 1.0) / std::sqrt(M_PI)), 1.0, 0.1);
  EXPECT_GT(r.packing_fraction, 0.63);
  EXPECT_LT(max_overlap(s), 1e-12);
}

// The jamming checks of docs/validation.md ("Compression and jamming") at a size the tests
// afford: the jamming density in the published range, the free-volume law on the way, the
// contact network isostatic within 1 % once rattlers are removed, rattlers a few percent.
template <int D>
void expect_jammed(ParticleSystem<D>& s, const CompressionSettings& c, double phi_lo,
                   double phi_hi) {
  const CompressionResult r = compress(s, c);
  ASSERT_EQ(r.stop_reason, "jammed");
  EXPECT_GT(r.packing_fraction, phi_lo);
  EXPECT_LT(r.packing_fraction, phi_hi);
  EXPECT_LT(max_overlap(s), 1e-12);
  // Free-volume law Z = D / (1 - phi / phi_J) (Salsburg and Wood 1962): phi / (1 - D / Z) is
  // phi_J all along the last decades of pressure.
  for (const CompressionRow& row : r.rows) {
    if (row.pressure < 1e4) continue;
    EXPECT_NEAR(row.packing_fraction / (1.0 - D / row.pressure), r.packing_fraction,
                2e-3 * r.packing_fraction)
        << "Z " << row.pressure;
  }
  const ContactNetwork net = contact_network(configuration_of(s), 1e4 / r.pressure);
  std::printf("phi_J %.5f collisions %llu z %.4f zb %.4f rattlers %.4f excess %lld\n",
              r.packing_fraction, static_cast<unsigned long long>(r.collisions), net.coordination,
              net.backbone_coordination, net.rattler_fraction,
              static_cast<long long>(net.excess_contacts));
  // Isostatic (backbone contacts = D (N - rattlers) - D) within 1.5 % at the default growth:
  // the deficit left by a finite rate shrinks as the growth slows (docs/validation.md).
  EXPECT_LE(std::abs(static_cast<double>(net.excess_contacts)),
            0.015 * static_cast<double>(net.backbone_contacts));
  EXPECT_NEAR(net.backbone_coordination, 2.0 * D, 0.015 * 2.0 * D);
  EXPECT_LT(net.rattler_fraction, 0.08);
  EXPECT_LT(net.largest_contact_gap, 1e-8);
  EXPECT_GT(net.smallest_open_gap, 1e-8);
}

TEST(Compression, JamsMonodisperseSpheres) {
  KAIROS_RELEASE_SUITE_ONLY();
  auto s = random_start<3>(400, 0.3, 4);
  expect_jammed<3>(s, CompressionSettings{}, 0.63, 0.66);
}

TEST(Compression, JamsBidisperseDisks) {
  auto s = random_start<2>(400, 0.5, 5, 1.4);
  expect_jammed<2>(s, CompressionSettings{}, 0.83, 0.855);
}

// A random start between walls on the faces `walled` (2k: the low face of axis k): the box
// widened by a diameter along each walled axis, the particles moved half a diameter in.
template <int D>
Environment<D> between_walls(ParticleSystem<D>& s, const std::vector<int>& walled) {
  Environment<D> env;
  for (const int f : walled) env.faces[f].kind = FaceKind::kWall;
  for (int a = 0; a < D; ++a) {
    if (env.periodic(a)) continue;
    s.box[a] += 1.0;
    for (Kinematics<D>& k : s.kinematics) k.pos[a] += 0.5;
    s.periodic[a] = false;
  }
  return env;
}

// The walls' smallest gap to a particle surface, relative to the radius (negative: overlap).
template <int D>
double worst_wall_gap(const ParticleSystem<D>& s, const Environment<D>& env) {
  double worst = kNever;
  for (const Kinematics<D>& k : s.kinematics) {
    for (int a = 0; a < D; ++a) {
      if (env.periodic(a)) continue;
      worst = std::min(
          {worst, (k.pos[a] - k.radius) / k.radius, (s.box[a] - k.pos[a] - k.radius) / k.radius});
    }
  }
  return worst;
}

// The contact network with walls, on configurations whose contacts are known: four unit disks
// filling a 2 x 2 box touch their two neighbours and two walls each.
TEST(ContactNetwork, WallContactsHoldParticlesAndTranslations) {
  Configuration<2> c;
  c.box = {2.0, 2.0};
  c.periodic = {false, false};
  for (const Vec<2> x : {Vec<2>{0.5, 0.5}, Vec<2>{1.5, 0.5}, Vec<2>{0.5, 1.5}, Vec<2>{1.5, 1.5}}) {
    c.position.push_back(x);
    c.species.push_back(0);
    c.radius.push_back(0.5);
  }
  const ContactNetwork closed = contact_network(c, 1e-8, {true, true, true, true});
  EXPECT_EQ(closed.contacts.size(), 4u);
  EXPECT_EQ(closed.wall_contacts.size(), 8u);
  EXPECT_EQ(closed.rattlers, 0u);
  EXPECT_DOUBLE_EQ(closed.coordination, 4.0);  // (2 x 4 + 8) / 4
  EXPECT_EQ(closed.backbone_wall_contacts, 8u);
  EXPECT_EQ(closed.excess_contacts, 4 + 8 - 2 * 4);  // no periodic axis: against D N'
  // Walls on x only, y periodic (the box 3 high): the y translation is free (P = 1). Each disk
  // touches two disks and one wall: D + 1, no rattler.
  Configuration<2> slab = c;
  slab.periodic = {false, true};
  slab.box[1] = 3.0;
  const ContactNetwork s1 = contact_network(slab, 1e-8, {true, true, false, false});
  EXPECT_EQ(s1.contacts.size(), 4u);
  EXPECT_EQ(s1.wall_contacts.size(), 4u);
  EXPECT_EQ(s1.rattlers, 0u);
  EXPECT_EQ(s1.excess_contacts, 4 + 4 - (2 * 4 - 1));
  EXPECT_THROW(contact_network(slab, 1e-8, {true, true, true, true}), std::invalid_argument);
  // Without disk 1, disk 0 moved 4e-9 off the x- wall: a wall gap relative to the diameter. Below
  // the tolerance it holds disk 0 (two walls, one disk); above it disk 0 is a rattler.
  Configuration<2> three = c;
  three.position.erase(three.position.begin() + 1);
  three.species.pop_back();
  three.radius.pop_back();
  three.position[0][0] += 4e-9;
  const ContactNetwork held = contact_network(three, 1e-8, {true, true, true, true});
  double gap = -1.0;
  for (const WallContact& k : held.wall_contacts)
    if (k.i == 0 && k.face == 0) gap = k.gap;
  EXPECT_NEAR(gap, 4e-9, 1e-15);
  EXPECT_EQ(held.rattlers, 0u);
  const ContactNetwork loose = contact_network(three, 1e-9, {true, true, true, true});
  EXPECT_EQ(loose.wall_contacts.size(), 5u);
  EXPECT_EQ(loose.rattler[0], 1);
  EXPECT_EQ(loose.rattlers, 1u);
  EXPECT_NEAR(loose.smallest_open_gap, 4e-9, 1e-15);
}

// Jamming in a closed box: the walls hold the packing as its particles do. Isostatic counting
// with walls: backbone contacts plus backbone wall contacts = D (N - rattlers) (no free
// translation). The walls' layering leaves the packing looser than in a periodic box.
TEST(Compression, JamsSpheresInAClosedBox) {
  KAIROS_RELEASE_SUITE_ONLY();
  auto s = random_start<3>(300, 0.3, 31);
  const Environment<3> env = between_walls<3>(s, {0, 1, 2, 3, 4, 5});
  const CompressionResult r = compress<3>(s, CompressionSettings{}, {}, env);
  ASSERT_EQ(r.stop_reason, "jammed");
  EXPECT_LT(max_overlap(s), 1e-12);
  EXPECT_GT(worst_wall_gap(s, env), -1e-12);
  Configuration<3> c = configuration_of(s);
  c.periodic.fill(false);
  std::array<bool, 6> walls;
  walls.fill(true);
  const ContactNetwork net = contact_network(c, 1e4 / r.pressure, walls);
  std::printf("closed box: phi_J %.5f z %.4f zb %.4f rattlers %.4f excess %lld walls %zu\n",
              r.packing_fraction, net.coordination, net.backbone_coordination, net.rattler_fraction,
              static_cast<long long>(net.excess_contacts), net.wall_contacts.size());
  EXPECT_GT(net.wall_contacts.size(), 40u);
  EXPECT_LE(std::abs(static_cast<double>(net.excess_contacts)),
            0.015 * static_cast<double>(net.backbone_contacts + net.backbone_wall_contacts));
  EXPECT_LT(net.largest_contact_gap, 1e-8);
  EXPECT_GT(net.smallest_open_gap, 1e-8);
  EXPECT_GT(r.packing_fraction, 0.50);
  EXPECT_LT(r.packing_fraction, 0.63);
}

// Two copies of a periodic state, one above the other along z (no overlap: the copies meet as
// the periodic images did).
template <int D>
ParticleSystem<D> stacked(ParticleSystem<D> s) {
  const std::size_t n = s.size();
  for (std::size_t i = 0; i < n; ++i) {
    Kinematics<D> k = s.kinematics[i];
    k.pos[D - 1] += s.box[D - 1];
    k.vel = -1.0 * k.vel;
    s.kinematics.push_back(k);
    s.mass.push_back(s.mass[i]);
    s.species.push_back(s.species[i]);
  }
  s.box[D - 1] *= 2.0;
  return s;
}

// Slow growth between walls on z, the other axes periodic: Z (the mean of the pressure on the
// walls along z and the virial along x and y) over the bulk equation of state at N V_particle /
// V. The walls' layers are a surface term: the excess over the bulk halves when the walls are
// twice as far apart.
double slit_excess(ParticleSystem<3> s, double eta) {
  const Environment<3> env = between_walls<3>(s, {4, 5});
  CompressionSettings c;
  c.growth_rate = 1e-3;
  c.thermostat_interval = 1.0;
  c.target_packing_fraction = eta + 0.01;
  const CompressionResult r = compress<3>(s, c, {}, env);
  EXPECT_GT(worst_wall_gap(s, env), -1e-12);
  EXPECT_LT(max_overlap(s), 1e-12);
  double sum = 0.0;
  int rows = 0;
  for (const CompressionRow& row : r.rows) {
    if (std::abs(row.packing_fraction - eta) > 0.01) continue;
    sum += row.pressure;
    ++rows;
  }
  EXPECT_GT(rows, 40);
  const double excess = sum / rows / klm_pressure(eta) - 1.0;
  std::printf("walls %.2f apart: eta %.2f Z %.4f KLM %.4f excess %.4f rows %d\n", s.box[2], eta,
              sum / rows, klm_pressure(eta), excess, rows);
  return excess;
}

TEST(Compression, SlowGrowthBetweenWallsIsTheBulkPlusASurfaceTerm) {
  KAIROS_RELEASE_SUITE_ONLY();
  const auto s = random_start<3>(1000, 0.3, 32);
  const double near = slit_excess(s, 0.40), far = slit_excess(stacked(s), 0.40);
  EXPECT_GT(near, 0.03);
  EXPECT_LT(near, 0.12);
  EXPECT_NEAR(far / near, 0.5, 0.15);
}

TEST(Compression, RefusesWhatItCannotDo) {
  auto s = random_start<3>(200, 0.3, 7);
  CompressionSettings c;
  c.target_packing_fraction = 0.2;
  EXPECT_THROW(compress(s, c), InputError);  // below the start
  c.target_packing_fraction = 0.72;
  // Growing until it jams takes the Release suite 30 s and the sanitized one 2 minutes.
  if (!testing::kSanitized) {
    try {
      compress(s, c);
      ADD_FAILURE() << "grew past jamming";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("jammed at packing fraction"), std::string::npos)
          << e.what();
    }
  }
  // Too few particles for 3 cells of the grown diameter per axis: a clear error, not the cell
  // list's.
  auto few = random_start<3>(20, 0.3, 9);
  CompressionSettings jam;
  try {
    compress(few, jam);
    ADD_FAILURE() << "jammed 20 spheres";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("use more particles"), std::string::npos) << e.what();
  }
  // A state bounded along z (exported from a run with walls) is not grown as periodic.
  auto bounded = random_start<3>(200, 0.3, 8);
  bounded.periodic[2] = false;
  EXPECT_THROW(compress(bounded, c), InputError);
  // Walls that move, or open faces: refused by the engine, naming what.
  auto walled = random_start<3>(200, 0.3, 8);
  Environment<3> piston = between_walls<3>(walled, {4, 5});
  piston.faces[5].wall.velocity[2] = -0.01;
  c.target_packing_fraction = 0.4;
  try {
    compress<3>(walled, c, {}, piston);
    ADD_FAILURE() << "grew against a piston";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("which moves"), std::string::npos) << e.what();
  }
}

// A random start denser than insertion reaches is grown to system.packing_fraction; [compress]
// with a density or pressure target of its own beside it is refused (it would silently replace
// the start's density); with jammed = true it grows through it.
TEST(Compression, RandomStartsAboveInsertionAreGrown) {
  const auto config = [](const std::string& compress) {
    return parse_config(
        "[system]\nparticles = 500\npacking_fraction = 0.5\nlattice = "
        "\"random\"\n" +
            compress,
        "test.toml");
  };
  EXPECT_TRUE(grows_random_start(config("")));
  EXPECT_TRUE(grows_random_start(config("[compress]\njammed = true\n")));
  EXPECT_THROW(grows_random_start(config("[compress]\npressure = 100.0\n")), InputError);
  EXPECT_THROW(grows_random_start(config("[compress]\npacking_fraction = 0.6\n")), InputError);
  EXPECT_FALSE(grows_random_start(parse_config(
      "[system]\nparticles = 500\npacking_fraction = 0.3\nlattice = \"random\"\n", "t")));
}

}  // namespace
}  // namespace kairos

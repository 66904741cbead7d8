// Image counters (engine/image_counters.hpp): the unwrapped positions they give move the
// centre of mass exactly as the conserved momentum says (which wrapped positions cannot), across
// renumbering, a restart and Lees-Edwards shear; particles/image in a GSD frame unwraps the
// float32 coordinate to the same place.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <vector>

#include "engine/event_engine.hpp"
#include "engine_fixtures.hpp"
#include "io/gsd_file.hpp"
#include "io/gsd_snapshot.hpp"
#include "scheduler/calendar_queue.hpp"

namespace kairos {
namespace {

template <int D>
using Engine = EventEngine<D, CalendarQueue>;

// Sum of m (x + image L) over the particles at the state's time, and the lab momentum, whose
// x part under shear counts each particle's images' speed (engine/image_counters.hpp).
template <int D>
struct Moments {
  Vec<D> mass_position{}, momentum{};
  double mass = 0.0;
};

template <int D>
Moments<D> moments(const ParticleSystem<D>& s, double image_speed = 0.0) {
  Moments<D> m;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const Vec<D> x = s.position(i, s.time);
    const Vec<D> v = s.velocity(i, s.time);
    for (int a = 0; a < D; ++a) {
      double u = x[a] + s.image[i][a] * s.box[a];
      double w = v[a];
      if (a == 0) {
        u += s.image[i][1] * image_speed * s.time;
        w += s.image[i][1] * image_speed;
      }
      m.mass_position[a] += s.mass[i] * u;
      m.momentum[a] += s.mass[i] * w;
    }
    m.mass += s.mass[i];
  }
  return m;
}

// The centre of mass of the unwrapped positions at the end is where the start's momentum
// carries it, to round-off; the particles crossed the box many times.
template <int D>
void centre_of_mass_follows_momentum(const Environment<D>& env, double eta, int events) {
  ParticleSystem<D> s = testing::lattice_system<D>(D == 3 ? 5 : 10, eta, 7, 2.0, 1.3);
  for (auto& k : s.kinematics) k.vel[0] += 0.7;  // a drift: the centre of mass moves
  if (env.shear_rate != 0.0)
    for (auto& k : s.kinematics) k.vel[0] += env.shear_rate * (k.pos[1] - 0.5 * s.box[1]);
  EngineOptions options;
  options.track_images = true;
  options.renumber_interval = 0.5;  // renumbered many times on the way
  Engine<D> engine(s, StartMode::kPredict, options, env);
  const double image_speed = env.shear_rate * s.box[1];
  const ParticleSystem<D> first = engine.export_state();
  const Moments<D> m0 = moments(first, image_speed);
  for (int e = 0; e < events; ++e) engine.step();
  const ParticleSystem<D> last = engine.export_state();
  ASSERT_EQ(last.image.size(), last.size());
  const Moments<D> m1 = moments(last, image_speed);
  const double t = last.time - first.time;
  int wrapped = 0;
  for (const auto& im : last.image)
    for (int a = 0; a < D; ++a) wrapped += std::abs(im[a]);
  EXPECT_GT(wrapped, static_cast<int>(last.size()));  // most particles crossed a face
  for (int a = 0; a < D; ++a) {
    const double expected = m0.mass_position[a] + m0.momentum[a] * t;
    const double scale = m0.mass * s.box[a] + std::abs(m0.momentum[a]) * t;
    EXPECT_NEAR(m1.mass_position[a], expected, 1e-11 * scale) << "axis " << a;
    EXPECT_NEAR(m1.momentum[a], m0.momentum[a], 1e-11 * m0.mass) << "axis " << a;
  }
}

TEST(ImageCounters, UnwrappedCentreOfMassMovesWithTheMomentum3D) {
  centre_of_mass_follows_momentum<3>(Environment<3>{}, 0.1, 40000);
}

TEST(ImageCounters, UnwrappedCentreOfMassMovesWithTheMomentum2D) {
  centre_of_mass_follows_momentum<2>(Environment<2>{}, 0.2, 40000);
}

TEST(ImageCounters, UnderShearTheLabFrameUnwrappedCentreOfMassMovesWithTheLabMomentum) {
  Environment<3> env3;
  env3.shear_rate = 0.9;
  centre_of_mass_follows_momentum<3>(env3, 0.1, 40000);
  Environment<2> env2;
  env2.shear_rate = 0.9;
  centre_of_mass_follows_momentum<2>(env2, 0.2, 40000);
}

TEST(ImageCounters, NotKeptUnlessAskedOrCarried) {
  const auto s = testing::lattice_system<3>(3, 0.2, 3);
  Engine<3> plain(s);
  EXPECT_TRUE(plain.export_state().image.empty());
  auto carried = s;
  carried.image.assign(s.size(), {1, -2, 3});
  Engine<3> kept(carried);
  const auto out = kept.export_state();
  ASSERT_EQ(out.image.size(), s.size());
  // The start wraps nothing here (lattice positions are inside the box): the counters as given.
  for (const auto& im : out.image) EXPECT_EQ(im, (std::array<std::int32_t, 3>{1, -2, 3}));
  carried.image.resize(2);
  EXPECT_THROW(Engine<3>{carried}, InputError);
}

TEST(ImageCounters, AStartOutsideTheBoxIsWrappedIntoIt) {
  auto s = testing::lattice_system<3>(3, 0.2, 5);
  const Vec<3> x0 = s.kinematics[4].pos;
  s.kinematics[4].pos[0] += 3.0 * s.box[0];
  s.kinematics[4].pos[2] -= 2.0 * s.box[2];
  EngineOptions options;
  options.track_images = true;
  options.renumber_interval = 0.0;
  Engine<3> engine(s, StartMode::kPredict, options);
  const auto out = engine.export_state();
  EXPECT_EQ(out.image[4], (std::array<std::int32_t, 3>{3, 0, -2}));
  EXPECT_NEAR(out.kinematics[4].pos[0], x0[0], 1e-12);
}

TEST(ImageCounters, KeptByRestartFilesAndWrittenAsHoomdImageFlags) {
  auto s = testing::lattice_system<3>(4, 0.15, 11);
  for (auto& k : s.kinematics) k.vel[1] += 1.5;
  EngineOptions options;
  options.track_images = true;
  Engine<3> engine(s, StartMode::kPredict, options);
  for (int e = 0; e < 20000; ++e) engine.step();
  const ParticleSystem<3> state = engine.export_state();
  const auto dir = std::filesystem::temp_directory_path() / "kairos_test_image_counters";
  std::filesystem::create_directories(dir);
  const auto restart = dir / "restart.gsd";
  write_restart(restart, state, std::mt19937_64(1));
  std::mt19937_64 rng;
  const ParticleSystem<3> back = read_restart<3>(restart, rng);
  ASSERT_EQ(back.image, state.image);
  // A resumed engine continues from the same counters.
  Engine<3> resumed(back, StartMode::kResume, options);
  EXPECT_EQ(resumed.export_state().image, state.image);

  // particles/image of a trajectory frame: float position + image * L is the unwrapped place.
  const auto traj = dir / "trajectory.gsd";
  {
    auto w = gsd::Writer::create(traj, "test");
    append_trajectory_frame(w, state);
    w.close();
  }
  const gsd::Reader r(traj);
  const auto pos = r.read<float>(0, "particles/position");
  const auto image = r.read<std::int32_t>(0, "particles/image");
  ASSERT_EQ(image.size(), 3 * state.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < state.size(); ++i) {
    const Vec<3> x = state.position(i, state.time);
    for (int a = 0; a < 3; ++a) {
      const double unwrapped = x[a] + state.image[i][a] * state.box[a];
      const double from_file =
          pos[3 * i + a] + 0.5 * state.box[a] + image[3 * i + a] * state.box[a];
      worst = std::max(worst, std::abs(unwrapped - from_file));
    }
  }
  EXPECT_LT(worst, 1e-5 * state.box[0]);  // float32 coordinates
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace kairos

// The engine's state read in blocks (EventEngine::state_blocks, for_each_block) is its whole
// export to the bit, in the caller's numbering, across block boundaries and after the engine
// renumbered its particles; a restart file written from the blocks is the file written from
// the whole export, byte for byte.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <random>
#include <string>

#include "core/state_blocks.hpp"
#include "engine/event_engine.hpp"
#include "engine_fixtures.hpp"
#include "io/gsd_snapshot.hpp"
#include "scheduler/calendar_queue.hpp"

namespace fs = std::filesystem;
using namespace kairos;

namespace {

std::string bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

using Engine = EventEngine<3, CalendarQueue>;

// 42^3 = 74 088 particles: two blocks, the second partial; run past a renumbering.
std::unique_ptr<Engine> running_engine() {
  EngineOptions options;
  options.renumber_interval = 0.5;  // collisions per particle between renumberings
  auto engine = std::make_unique<Engine>(kairos::testing::lattice_system<3>(42, 0.3, 17, 1.5, 1.2),
                                         StartMode::kPredict, options);
  while (engine->counters().collisions < 60000) engine->step();
  return engine;
}

}  // namespace

TEST(StateBlocks, BlocksAreTheWholeExport) {
  const auto holder = running_engine();
  const Engine& engine = *holder;
  const ParticleSystem<3> whole = engine.export_state();
  const StateBlocks<3> blocks = engine.state_blocks();
  ASSERT_EQ(blocks.particles, whole.size());
  ASSERT_GT(whole.size(), StateBlocks<3>::kBlock);
  std::size_t seen = 0;
  blocks.for_each([&](const ParticleSystem<3>& part, std::size_t first) {
    ASSERT_EQ(first, seen);
    for (std::size_t j = 0; j < part.size(); ++j) {
      const std::size_t i = first + j;
      ASSERT_EQ(part.kinematics[j].pos, whole.kinematics[i].pos) << i;
      ASSERT_EQ(part.kinematics[j].vel, whole.kinematics[i].vel) << i;
      ASSERT_EQ(part.kinematics[j].time, whole.kinematics[i].time) << i;
      ASSERT_EQ(part.kinematics[j].radius, whole.kinematics[i].radius) << i;
      ASSERT_EQ(part.mass[j], whole.mass[i]);
      ASSERT_EQ(part.species[j], whole.species[i]);
      ASSERT_EQ(part.collision_count[j], whole.collision_count[i]);
      ASSERT_EQ(part.events[j].time, whole.events[i].time);
      ASSERT_EQ(part.events[j].partner, whole.events[i].partner);
      ASSERT_EQ(part.events[j].partner_count, whole.events[i].partner_count);
      ASSERT_EQ(part.cell[j], whole.cell[i]);
      ASSERT_EQ(part.order[j], whole.order[i]);
    }
    seen += part.size();
  });
  EXPECT_EQ(seen, whole.size());
  // The engine did renumber: its order is not the identity.
  bool identity = true;
  for (std::size_t k = 0; k < whole.order.size(); ++k) identity = identity && whole.order[k] == k;
  EXPECT_FALSE(identity);
}

TEST(StateBlocks, ForEachBlockIsCurrentPositionsVelocitiesAndMasses) {
  const auto holder = running_engine();
  const Engine& engine = *holder;
  const auto x = engine.current_positions();
  const auto v = engine.current_velocities();
  const ParticleSystem<3> whole = engine.export_state(/*with_zones=*/false);
  std::size_t seen = 0;
  engine.for_each_block([&](std::size_t first, auto bx, auto bv, auto bm) {
    ASSERT_EQ(first, seen);
    for (std::size_t j = 0; j < bx.size(); ++j) {
      ASSERT_EQ(bx[j], x[first + j]);
      ASSERT_EQ(bv[j], v[first + j]);
      ASSERT_EQ(bm[j], whole.mass[first + j]);
    }
    seen += bx.size();
  });
  EXPECT_EQ(seen, x.size());
}

TEST(StateBlocks, RestartFromBlocksIsTheFileFromTheWholeExport) {
  const auto holder = running_engine();
  const Engine& engine = *holder;
  const fs::path dir = fs::temp_directory_path() / ("kairos_blocks_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::mt19937_64 rng(3);
  write_restart<3>(dir / "whole.gsd", engine.export_state(), rng);
  write_restart<3>(dir / "blocks.gsd", engine.state_blocks(), rng);
  EXPECT_EQ(bytes_of(dir / "whole.gsd"), bytes_of(dir / "blocks.gsd"));
  {
    auto a = gsd::Writer::create(dir / "a.gsd", "test");
    auto b = gsd::Writer::create(dir / "b.gsd", "test");
    append_trajectory_frame<3>(a, engine.export_state(false));
    append_trajectory_frame<3>(b, engine.state_blocks(false));
  }
  EXPECT_EQ(bytes_of(dir / "a.gsd"), bytes_of(dir / "b.gsd"));
  // And it resumes: the engine rebuilt from it continues as the original does.
  std::mt19937_64 back;
  EngineOptions options;
  options.renumber_interval = 0.5;
  Engine resumed(read_restart<3>(dir / "blocks.gsd", back), StartMode::kResume, options);
  Engine& original = *holder;
  for (int k = 0; k < 20000; ++k) {
    original.step();
    resumed.step();
  }
  EXPECT_EQ(original.export_state().kinematics[123].pos,
            resumed.export_state().kinematics[123].pos);
  EXPECT_EQ(original.counters().collisions, resumed.counters().collisions);
  fs::remove_all(dir);
}

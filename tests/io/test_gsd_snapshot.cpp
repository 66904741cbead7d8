// Bonds, pair zones and step counters in GSD trajectory frames, restart files and initial
// states (io/gsd_snapshot.hpp).
#include "io/gsd_snapshot.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "init/initial_state.hpp"
#include "init/initial_state_file.hpp"
#include "io/gsd_file.hpp"

namespace fs = std::filesystem;

namespace kairos {
namespace {

class GsdSnapshot : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("kairos_gsd_snapshot_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path file(const std::string& name) const { return dir_ / name; }

  fs::path dir_;
};

// A chain system as the engine would export it: scheduler arrays sized, nothing pending.
template <int D>
ParticleSystem<D> chain_system(std::uint64_t n = 60, std::uint64_t length = 6) {
  SystemConfig sys;
  sys.dimension = D;
  sys.particles = n;
  sys.packing_fraction = 0.1;
  sys.chain_length = length;
  std::mt19937_64 rng(3);
  ParticleSystem<D> s = to_particle_system<D>(make_initial_state<D>(sys, rng));
  s.events.assign(n, EventSlot{});
  s.cell.assign(n, 0);
  s.collision_count.assign(n, 0);
  s.time = 0.25;
  return s;
}

// Copies chunk `name` of frame 0 from `r` to `w`; `edit` (optional) may change its raw bytes.
void copy_chunk(const gsd::Reader& r, gsd::Writer& w, const std::string& name,
                const std::function<void(char*, std::size_t)>& edit = {}) {
  const auto info = r.find(0, name);
  ASSERT_TRUE(info) << name;
  const auto copy = [&](auto zero) {
    using T = decltype(zero);
    auto v = r.read<T>(0, name);
    if (edit) edit(reinterpret_cast<char*>(v.data()), v.size() * sizeof(T));
    w.write_chunk(name, info->N, info->M, v.data());
  };
  switch (info->type) {
    case gsd::Type::uint8:
      copy(std::uint8_t{});
      break;
    case gsd::Type::uint32:
      copy(std::uint32_t{});
      break;
    case gsd::Type::uint64:
      copy(std::uint64_t{});
      break;
    case gsd::Type::int8:
      copy(std::int8_t{});
      break;
    case gsd::Type::float32:
      copy(float{});
      break;
    case gsd::Type::float64:
      copy(double{});
      break;
    default:
      FAIL() << name << ": unexpected type";
  }
}

// Copies frame 0 of `from` to `to` without the chunks in `drop`, and with kairos/format set to
// `format`: a restart file as an older Kairos wrote it (without kairos/checksum, which format 7
// added).
void copy_frame(const fs::path& from, const fs::path& to, const std::set<std::string>& drop,
                std::uint32_t format) {
  const gsd::Reader r(from);
  auto w = gsd::Writer::create(to, "kairos-test");
  for (const std::string& name : r.chunk_names()) {
    if (!r.find(0, name) || drop.count(name) != 0 || name == "kairos/checksum") continue;
    if (name == "kairos/format")
      w.write_chunk(name, 1, 1, &format);
    else
      copy_chunk(r, w, name);
  }
  w.end_frame();
}

template <int D>
void expect_round_trip(const fs::path& path, const ParticleSystem<D>& s) {
  std::mt19937_64 rng(5), back;
  rng.discard(3);
  write_restart<D>(path, s, rng);
  const ParticleSystem<D> r = read_restart<D>(path, back);
  EXPECT_EQ(back, rng);
  EXPECT_EQ(r.bonds, s.bonds);
  EXPECT_EQ(r.bond_types, s.bond_types);
  EXPECT_EQ(r.zones, s.zones);
  EXPECT_EQ(r.counters.step_crossings, s.counters.step_crossings);
  EXPECT_EQ(r.counters.step_bounces, s.counters.step_bounces);
  EXPECT_EQ(r.counters.collisions, s.counters.collisions);
  ASSERT_EQ(r.size(), s.size());
  for (std::size_t i = 0; i < s.size(); ++i) EXPECT_EQ(r.kinematics[i].pos, s.kinematics[i].pos);
}

TEST_F(GsdSnapshot, RestartRoundTripsBondsZonesAndStepCounters3D) {
  auto s = chain_system<3>();
  ASSERT_EQ(s.bonds.size(), 50u);
  s.counters.collisions = 11;
  s.counters.step_crossings = 123456789012ull;
  s.counters.step_bounces = 42;
  s.zones = std::vector<PairZone>{{0, 1, 1}, {3, 17, 2}, {5, 59, 7}};
  expect_round_trip<3>(file("restart.gsd"), s);
  const gsd::Reader r(file("restart.gsd"));
  EXPECT_EQ(r.read<std::uint32_t>(0, "kairos/format"), std::vector<std::uint32_t>{7});
  EXPECT_EQ(r.read<std::uint64_t>(0, "kairos/state/zone_count"), std::vector<std::uint64_t>{3});
  const auto zones = r.find(0, "kairos/state/zones");
  ASSERT_TRUE(zones);
  EXPECT_EQ(zones->N, 3u);
  EXPECT_EQ(zones->M, 3u);
}

TEST_F(GsdSnapshot, StepCountersAreUint64) {
  auto s = chain_system<2>();
  s.counters.step_crossings = 3;
  s.counters.step_bounces = 4;
  write_restart<2>(file("r.gsd"), s, std::mt19937_64{});
  const gsd::Reader r(file("r.gsd"));
  EXPECT_EQ(r.read<std::uint64_t>(0, "kairos/state/step_counters"),
            (std::vector<std::uint64_t>{3, 4}));
}

TEST_F(GsdSnapshot, RestartRoundTripsPresentEmptyAndAbsentZones2D) {
  auto s = chain_system<2>(48, 8);
  s.zones = std::vector<PairZone>{};
  expect_round_trip<2>(file("empty.gsd"), s);
  {
    const gsd::Reader r(file("empty.gsd"));
    EXPECT_TRUE(r.find(0, "kairos/state/zone_count"));
    EXPECT_FALSE(r.find(0, "kairos/state/zones"));
  }
  s.zones.reset();
  expect_round_trip<2>(file("absent.gsd"), s);
  {
    const gsd::Reader r(file("absent.gsd"));
    EXPECT_FALSE(r.find(0, "kairos/state/zone_count"));
    EXPECT_FALSE(r.find(0, "kairos/state/zones"));
  }
  // No bonds at all: no bonds/ chunks.
  s.bonds.clear();
  s.bond_types.clear();
  expect_round_trip<2>(file("plain.gsd"), s);
  const gsd::Reader r(file("plain.gsd"));
  for (const std::string& name : r.chunk_names()) EXPECT_NE(name.rfind("bonds/", 0), 0u) << name;
}

TEST_F(GsdSnapshot, BondTypesWithoutBondsRoundTrip) {
  auto s = chain_system<3>();
  s.bonds.clear();
  s.bond_types = {"backbone", "side"};
  expect_round_trip<3>(file("types.gsd"), s);
}

TEST_F(GsdSnapshot, ReadsFormat3RestartsWithoutTheNewChunks) {
  auto s = chain_system<3>();
  s.counters.step_crossings = 9;
  s.zones = std::vector<PairZone>{{0, 1, 1}};
  write_restart<3>(file("v4.gsd"), s, std::mt19937_64{});
  copy_frame(file("v4.gsd"), file("v3.gsd"),
             {"kairos/state/step_counters", "kairos/state/zone_count", "kairos/state/zones",
              "bonds/N", "bonds/types", "bonds/typeid", "bonds/group"},
             3);
  std::mt19937_64 rng;
  const auto r = read_restart<3>(file("v3.gsd"), rng);
  EXPECT_FALSE(r.zones.has_value());
  EXPECT_EQ(r.counters.step_crossings, 0u);
  EXPECT_EQ(r.counters.step_bounces, 0u);
  EXPECT_TRUE(r.bonds.empty());
  EXPECT_TRUE(r.bond_types.empty());
  EXPECT_EQ(r.size(), s.size());

  for (const std::uint32_t bad : {2u, 8u}) {
    copy_frame(file("v4.gsd"), file("bad.gsd"), {}, bad);
    try {
      (void)read_restart<3>(file("bad.gsd"), rng);
      ADD_FAILURE() << "format " << bad << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("restart format version " + std::to_string(bad)),
                std::string::npos)
          << e.what();
    }
  }
}

TEST_F(GsdSnapshot, DamagedBondsAndZonesAreInputErrors) {
  std::mt19937_64 rng;
  auto s = chain_system<3>();
  s.bonds.push_back({3, 60, 0});  // particle 60 of 60
  write_restart<3>(file("a.gsd"), s, rng);
  EXPECT_THROW((void)read_restart<3>(file("a.gsd"), rng), InputError);

  s = chain_system<3>();
  s.bonds.push_back({3, 4, 1});  // one bond type only
  write_restart<3>(file("b.gsd"), s, rng);
  EXPECT_THROW((void)read_restart<3>(file("b.gsd"), rng), InputError);

  s = chain_system<3>();
  s.bonds.push_back({4, 4, 0});
  write_restart<3>(file("c.gsd"), s, rng);
  EXPECT_THROW((void)read_restart<3>(file("c.gsd"), rng), InputError);

  s = chain_system<3>();
  s.zones = std::vector<PairZone>{{5, 2, 1}};  // i > j
  write_restart<3>(file("d.gsd"), s, rng);
  EXPECT_THROW((void)read_restart<3>(file("d.gsd"), rng), InputError);

  s.zones = std::vector<PairZone>{{5, 60, 1}};
  write_restart<3>(file("e.gsd"), s, rng);
  EXPECT_THROW((void)read_restart<3>(file("e.gsd"), rng), InputError);

  // zone_count larger than the zones chunk
  s.zones = std::vector<PairZone>{{1, 2, 1}};
  write_restart<3>(file("f.gsd"), s, rng);
  copy_frame(file("f.gsd"), file("g.gsd"), {"kairos/state/zones"}, 4);
  EXPECT_THROW((void)read_restart<3>(file("g.gsd"), rng), InputError);
}

TEST_F(GsdSnapshot, TrajectoryWritesBondsInFrameZeroAndInitialStateReadsThem) {
  auto s = chain_system<3>();
  {
    auto w = gsd::Writer::create(file("traj.gsd"), "kairos-test");
    append_trajectory_frame<3>(w, s);
    s.time = 1.0;
    append_trajectory_frame<3>(w, s);
  }
  const gsd::Reader r(file("traj.gsd"));
  ASSERT_EQ(r.frame_count(), 2u);
  EXPECT_EQ(r.read<std::uint32_t>(0, "bonds/N"), std::vector<std::uint32_t>{50});
  EXPECT_FALSE(r.find(1, "bonds/N"));
  const auto group = r.read<std::uint32_t>(0, "bonds/group");
  ASSERT_EQ(group.size(), 100u);
  EXPECT_EQ(group[0], 0u);
  EXPECT_EQ(group[1], 1u);
  EXPECT_EQ(group[10], 6u);  // bond 5: first of chain 1
  EXPECT_EQ(group[11], 7u);

  bool has_velocities = false;
  const auto init = read_initial_state<3>(file("traj.gsd"), has_velocities);
  EXPECT_EQ(init.bonds, s.bonds);
  EXPECT_EQ(init.bond_types, s.bond_types);

  // A restart file is also an initial state.
  write_restart<3>(file("restart.gsd"), s, std::mt19937_64{});
  const auto from_restart = read_initial_state<3>(file("restart.gsd"), has_velocities);
  EXPECT_EQ(from_restart.bonds, s.bonds);
  EXPECT_EQ(from_restart.bond_types, s.bond_types);
  EXPECT_EQ(to_particle_system<3>(from_restart).bonds, s.bonds);
}

// A minimal HOOMD frame of 4 particles with the given bond chunks.
void write_bonded_frame(const fs::path& path, const std::vector<std::uint32_t>& group,
                        const std::vector<std::uint32_t>& type_id,
                        const std::vector<std::string>& types) {
  auto w = gsd::Writer::create(path, "kairos-test");
  const std::uint8_t dims = 2;
  const float box[6] = {10, 10, 0, 0, 0, 0};
  const std::uint32_t n = 4;
  const float pos[12] = {0, 0, 0, 1.5f, 0, 0, 3, 0, 0, 4.5f, 0, 0};
  w.write_chunk("configuration/dimensions", 1, 1, &dims);
  w.write_chunk("configuration/box", 6, 1, box);
  w.write_chunk("particles/N", 1, 1, &n);
  w.write_chunk("particles/position", n, 3, pos);
  const auto nb = static_cast<std::uint32_t>(group.size() / 2);
  w.write_chunk("bonds/N", 1, 1, &nb);
  w.write_chunk("bonds/group", nb, 2, group.data());
  if (!type_id.empty()) w.write_chunk("bonds/typeid", nb, 1, type_id.data());
  if (!types.empty()) {
    std::vector<std::int8_t> raw(types.size() * 8, 0);
    for (std::size_t t = 0; t < types.size(); ++t)
      std::copy(types[t].begin(), types[t].end(), raw.begin() + static_cast<std::ptrdiff_t>(8 * t));
    w.write_chunk("bonds/types", types.size(), 8, raw.data());
  }
  w.end_frame();
}

TEST_F(GsdSnapshot, InitialStateBondsFromHoomdFiles) {
  bool v = false;
  write_bonded_frame(file("plain.gsd"), {0, 1, 1, 2, 2, 3}, {}, {});
  auto s = read_initial_state<2>(file("plain.gsd"), v);
  EXPECT_EQ(s.bonds, (std::vector<Bond>{{0, 1, 0}, {1, 2, 0}, {2, 3, 0}}));
  EXPECT_EQ(s.bond_types, std::vector<std::string>{"backbone"});

  write_bonded_frame(file("typed.gsd"), {0, 1, 3, 2}, {1, 0}, {"a", "bb"});
  s = read_initial_state<2>(file("typed.gsd"), v);
  EXPECT_EQ(s.bonds, (std::vector<Bond>{{0, 1, 1}, {3, 2, 0}}));
  EXPECT_EQ(s.bond_types, (std::vector<std::string>{"a", "bb"}));

  const auto message = [&](const fs::path& p) -> std::string {
    try {
      (void)read_initial_state<2>(p, v);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  write_bonded_frame(file("range.gsd"), {0, 1, 1, 4}, {}, {});
  EXPECT_NE(message(file("range.gsd")).find("bond 1 (1, 4)"), std::string::npos)
      << message(file("range.gsd"));
  EXPECT_NE(message(file("range.gsd")).find("system.initial_state"), std::string::npos);
  write_bonded_frame(file("self.gsd"), {2, 2}, {}, {});
  EXPECT_NE(message(file("self.gsd")).find("itself"), std::string::npos);
  write_bonded_frame(file("type.gsd"), {0, 1}, {2}, {"a", "b"});
  EXPECT_NE(message(file("type.gsd")).find("typeid 2"), std::string::npos);
}

// Copies frame 0 of `from` to `to` as it is, kairos/checksum included, but for one byte of
// chunk `name` changed (its first, or `byte`).
void copy_with_flipped_byte(const fs::path& from, const fs::path& to, const std::string& name,
                            std::size_t byte = 0) {
  const gsd::Reader r(from);
  auto w = gsd::Writer::create(to, "kairos-test");
  for (const std::string& chunk : r.chunk_names()) {
    if (!r.find(0, chunk)) continue;
    copy_chunk(r, w, chunk, [&](char* data, std::size_t bytes) {
      if (chunk == name && byte < bytes) data[byte] = static_cast<char>(data[byte] ^ 0x04);
    });
  }
  w.end_frame();
}

std::string restart_error(const fs::path& path) {
  std::mt19937_64 rng;
  try {
    (void)read_restart<3>(path, rng);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

// A restart file carries the CRC-32 of all its other chunks: one byte changed in any chunk, even
// to a plausible value (a mass of 1.0 becoming 1.0000000000000009), makes it a damaged file,
// as a restart and as an initial state. It used to be accepted and change the run.
TEST_F(GsdSnapshot, RestartChecksumCoversEveryChunk) {
  auto s = chain_system<3>();
  s.zones = std::vector<PairZone>{{0, 1, 1}};
  write_restart<3>(file("good.gsd"), s, std::mt19937_64{});
  ASSERT_EQ(restart_error(file("good.gsd")), "(accepted)");
  const gsd::Reader r(file("good.gsd"));
  std::size_t checked = 0;
  for (const std::string& name : r.chunk_names()) {
    const auto info = r.find(0, name);
    if (name == "kairos/checksum" || !info || info->N * info->M == 0) continue;
    copy_with_flipped_byte(file("good.gsd"), file("bad.gsd"), name);
    const std::string expected =
        "restart file '" + file("bad.gsd").string() + "' is damaged: checksum mismatch";
    EXPECT_NE(restart_error(file("bad.gsd")).find(expected), std::string::npos)
        << name << ": " << restart_error(file("bad.gsd"));
    ++checked;
  }
  EXPECT_GT(checked, 30u);

  copy_with_flipped_byte(file("good.gsd"), file("mass.gsd"), "kairos/mass", 8 * 17);
  bool v = false;
  try {
    (void)read_initial_state<3>(file("mass.gsd"), v);
    ADD_FAILURE() << "a damaged restart file was accepted as an initial state";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("system.initial_state '" + file("mass.gsd").string() +
                                         "' is damaged: checksum mismatch"),
              std::string::npos)
        << e.what();
  }
  EXPECT_NO_THROW((void)read_initial_state<3>(file("good.gsd"), v));

  // Format 7 without its checksum is damaged too; format 6 (before checksums) is read.
  copy_frame(file("good.gsd"), file("none.gsd"), {}, 7);
  EXPECT_NE(restart_error(file("none.gsd"))
                .find("is damaged: restart format 7 but no "
                      "kairos/checksum chunk"),
            std::string::npos)
      << restart_error(file("none.gsd"));
  copy_frame(file("good.gsd"), file("v6.gsd"), {}, 6);
  EXPECT_EQ(restart_error(file("v6.gsd")), "(accepted)");
}

// A one-frame 3D HOOMD file whose particles/N claims `claimed` particles, with `rows` positions
// (0: no positions chunk) and, when `typeids` > 0, that many particles/typeid values.
void write_claiming_frame(const fs::path& path, std::uint32_t claimed, std::uint32_t rows,
                          std::uint32_t typeids = 0, std::array<float, 3> tilt = {}) {
  auto w = gsd::Writer::create(path, "kairos-test");
  const std::uint8_t dims = 3;
  const float box[6] = {10, 10, 10, tilt[0], tilt[1], tilt[2]};
  w.write_chunk("configuration/dimensions", 1, 1, &dims);
  w.write_chunk("configuration/box", 6, 1, box);
  w.write_chunk("particles/N", 1, 1, &claimed);
  std::vector<float> pos(3 * std::size_t{rows});
  for (std::size_t i = 0; i < rows; ++i) pos[3 * i] = 1.5f * static_cast<float>(i) - 4.0f;
  if (rows > 0) w.write_chunk("particles/position", rows, 3, pos.data());
  const std::vector<std::uint32_t> type_id(typeids, 0);
  if (typeids > 0) w.write_chunk("particles/typeid", typeids, 1, type_id.data());
  w.end_frame();
}

std::string initial_state_error(const fs::path& path) {
  bool v = false;
  try {
    (void)read_initial_state<3>(path, v);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

// A small file claiming 5e7 particles is refused before anything is allocated for them (the
// positions chunk must hold them); it used to take 2.4 GB first.
TEST_F(GsdSnapshot, ClaimedParticleCountIsCheckedAgainstTheStoredPositions) {
  write_claiming_frame(file("none.gsd"), 50'000'000, 0);
  EXPECT_NE(initial_state_error(file("none.gsd"))
                .find("system.initial_state '" + file("none.gsd").string() +
                      "': particles/N = 50000000 but the file has no chunk 'particles/position'"),
            std::string::npos)
      << initial_state_error(file("none.gsd"));
  write_claiming_frame(file("few.gsd"), 50'000'000, 4);
  EXPECT_NE(initial_state_error(file("few.gsd"))
                .find("particles/N = 50000000 but chunk 'particles/position' holds 4 x 3 values, "
                      "not 50000000 x 3"),
            std::string::npos)
      << initial_state_error(file("few.gsd"));

  // A restart file claiming more particles than its exact positions hold.
  auto w = gsd::Writer::create(file("claim.gsd"), "kairos-test");
  const std::uint32_t format = 6, claimed = 50'000'000;
  const std::uint8_t dims = 3;
  w.write_chunk("kairos/format", 1, 1, &format);
  w.write_chunk("kairos/dimension", 1, 1, &dims);
  w.write_chunk("particles/N", 1, 1, &claimed);
  w.end_frame();
  w.close();
  std::mt19937_64 rng;
  try {
    (void)read_restart<3>(file("claim.gsd"), rng);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "particles/N = 50000000 but the file has no chunk 'kairos/state/position'"),
              std::string::npos)
        << e.what();
  }
}

// particles/typeid must hold one value per particle (a shorter one was read out of bounds).
TEST_F(GsdSnapshot, InitialStateTypeidOfTheWrongSizeIsAnInputError) {
  write_claiming_frame(file("short.gsd"), 4, 4, 2);
  EXPECT_NE(initial_state_error(file("short.gsd"))
                .find("chunk 'particles/typeid' holds 2 values, expected 4"),
            std::string::npos)
      << initial_state_error(file("short.gsd"));
  write_claiming_frame(file("right.gsd"), 4, 4, 4);
  EXPECT_EQ(initial_state_error(file("right.gsd")), "(accepted)");
}

// A triclinic box (nonzero tilt factors) is refused, naming the file and the factors: it used
// to run as the rectangular box of its edges.
TEST_F(GsdSnapshot, TiltedBoxIsRefused) {
  write_claiming_frame(file("tilt.gsd"), 4, 4, 0, {0.5f, 0.0f, -0.25f});
  EXPECT_NE(initial_state_error(file("tilt.gsd"))
                .find("system.initial_state '" + file("tilt.gsd").string() +
                      "': configuration/box has tilt factors xy = 0.5, xz = 0, yz = -0.25"),
            std::string::npos)
      << initial_state_error(file("tilt.gsd"));
  write_claiming_frame(file("nan.gsd"), 4, 4, 0, {0.0f, std::nanf(""), 0.0f});
  EXPECT_NE(initial_state_error(file("nan.gsd")).find("tilt factors"), std::string::npos);
  write_claiming_frame(file("flat.gsd"), 4, 4, 0, {-0.0f, 0.0f, 0.0f});
  EXPECT_EQ(initial_state_error(file("flat.gsd")), "(accepted)");
}

}  // namespace
}  // namespace kairos

// Cross-checks of the GSD file layer against Debian's python3-gsd (2.7), in both directions.
// python3-gsd is a declared dependency: if KAIROS_PYTHON cannot import it, these tests fail.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "init/initial_state.hpp"
#include "io/config.hpp"
#include "io/gsd_file.hpp"
#include "io/gsd_snapshot.hpp"

#ifndef KAIROS_PYTHON
#define KAIROS_PYTHON "/usr/bin/python3"
#endif

namespace fs = std::filesystem;
using namespace kairos::gsd;
using kairos::ParticleSystem;

namespace {

struct PythonRun {
  int status;
  std::string output;
};

std::string quote(const std::string& s) {
  std::string q = "'";
  for (const char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

class GsdInterop : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("kairos_gsd_interop_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const PythonRun check = python("import gsd, gsd.fl, gsd.hoomd\nprint(gsd.__version__)\n", {});
    ASSERT_EQ(check.status, 0) << "python3-gsd is a required test dependency, but " KAIROS_PYTHON
                                  " cannot import gsd (install the Debian package "
                                  "python3-gsd):\n"
                               << check.output;
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path file(const std::string& name) const { return dir_ / name; }

  // Runs a Python script with the given arguments; returns its exit status and output.
  PythonRun python(const std::string& code, const std::vector<fs::path>& args) {
    const fs::path script = dir_ / ("script" + std::to_string(scripts_++) + ".py");
    std::ofstream(script) << code;
    std::string command = std::string(KAIROS_PYTHON) + " " + quote(script.string());
    for (const auto& a : args) {
      command += ' ';
      command += quote(a.string());
    }
    command += " 2>&1";
    PythonRun run{-1, ""};
    FILE* pipe = ::popen(command.c_str(), "r");
    if (pipe == nullptr) return run;
    char buffer[4096];
    std::size_t n = 0;
    while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) run.output.append(buffer, n);
    run.status = ::pclose(pipe);
    return run;
  }

  fs::path dir_;
  int scripts_ = 0;
};

#define EXPECT_PYTHON_OK(run) EXPECT_EQ((run).status, 0) << (run).output

// Values shared by the C++ and Python sides: position k of particle i in frame f.
float position(std::uint64_t f, std::size_t i, std::size_t k) {
  return static_cast<float>(f) + 0.25f * static_cast<float>(i) + static_cast<float>(k);
}

void write_hoomd_frame(Writer& w, std::uint64_t f, bool with_types) {
  const std::uint64_t step = 1000 * (f + 1);
  const std::uint8_t dimensions = 3;
  const float box[6] = {10.0f, 11.0f, 12.0f + static_cast<float>(f), 0.0f, 0.0f, 0.0f};
  const std::uint32_t N = 4;
  std::vector<float> pos(3 * N);
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t k = 0; k < 3; ++k) pos[3 * i + k] = position(f, i, k);
  const std::int8_t types[2][3] = {{'A', 0, 0}, {'B', 'B', 0}};
  const double time = 0.5 + static_cast<double>(f);
  w.write_chunk("configuration/step", 1, 1, &step);
  w.write_chunk("configuration/dimensions", 1, 1, &dimensions);
  w.write_chunk("configuration/box", 6, 1, box);
  w.write_chunk("particles/N", 1, 1, &N);
  w.write_chunk("particles/position", N, 3, pos.data());
  if (with_types) w.write_chunk("particles/types", 2, 3, &types[0][0]);
  w.write_chunk("log/time", 1, 1, &time);
  w.end_frame();
}

const char* const kCheckHoomd = R"PY(
import sys
import numpy as np
import gsd.fl, gsd.hoomd

name, nframes = sys.argv[1], int(sys.argv[2])
with gsd.fl.open(name=name, mode='rb') as f:
    assert f.gsd_version == (2, 0), f.gsd_version
    assert f.application == 'kairos-test', f.application
    assert f.schema == 'hoomd' and tuple(f.schema_version) == (1, 4)
    assert f.nframes == nframes, f.nframes
    assert f.read_chunk(frame=0, name='particles/types').dtype == np.int8
    assert not f.chunk_exists(frame=1, name='particles/types')
with gsd.hoomd.open(name, 'rb') as traj:
    assert len(traj) == nframes, len(traj)
    for f in range(nframes):
        s = traj[f]
        assert s.configuration.step == 1000 * (f + 1), s.configuration.step
        assert s.configuration.dimensions == 3
        np.testing.assert_array_equal(s.configuration.box, [10, 11, 12 + f, 0, 0, 0])
        assert s.particles.N == 4
        assert s.particles.types == ['A', 'BB'], s.particles.types
        expected = np.array([[f + 0.25 * i + k for k in range(3)] for i in range(4)], np.float32)
        assert s.particles.position.dtype == np.float32
        np.testing.assert_array_equal(s.particles.position, expected)
        assert s.log['time'].dtype == np.float64
        np.testing.assert_array_equal(s.log['time'], [0.5 + f])
print('ok')
)PY";

TEST_F(GsdInterop, PythonReadsOurHoomdFrames) {
  {
    auto w = Writer::create(file("ours.gsd"), "kairos-test");
    write_hoomd_frame(w, 0, true);
    write_hoomd_frame(w, 1, false);
  }
  EXPECT_PYTHON_OK(python(kCheckHoomd, {file("ours.gsd"), "2"}));
  {
    auto w = Writer::open_append(file("ours.gsd"));
    write_hoomd_frame(w, 2, false);
  }
  EXPECT_PYTHON_OK(python(kCheckHoomd, {file("ours.gsd"), "3"}));
}

// Both libraries append to the same file, each growing the index and the namelist.
TEST_F(GsdInterop, AlternatingAppends) {
  {
    auto w = Writer::create(file("mixed.gsd"), "kairos-test");
    write_hoomd_frame(w, 0, true);
  }
  const char* const append = R"PY(
import sys
import numpy as np
import gsd.fl
with gsd.fl.open(name=sys.argv[1], mode='ab') as f:
    first = f.nframes
    for frame in range(first, first + 100):
        f.write_chunk(name='configuration/step', data=np.array([1000 * (frame + 1)], np.uint64))
        f.write_chunk(name='extra/python/a_fairly_long_quantity_name_%d' % (frame % 40),
                      data=np.array([frame, -frame], np.int64))
        f.end_frame()
)PY";
  const std::string name_prefix = "extra/kairos/another_fairly_long_quantity_name_";
  for (int round = 0; round < 2; ++round) {
    ASSERT_EQ(python(append, {file("mixed.gsd")}).status, 0);
    auto w = Writer::open_append(file("mixed.gsd"));
    ASSERT_EQ(w.frame_count(), 101u + 200u * static_cast<unsigned>(round));
    for (int i = 0; i < 100; ++i) {
      const auto frame = static_cast<std::int64_t>(w.frame_count());
      const std::uint64_t step = 1000 * static_cast<std::uint64_t>(frame + 1);
      const std::int64_t values[2] = {frame, -frame};
      w.write_chunk("configuration/step", 1, 1, &step);
      w.write_chunk(name_prefix + std::to_string(frame % 40), 1, 2, values);
      w.end_frame();
    }
  }
  const char* const check = R"PY(
import sys
import numpy as np
import gsd.fl, gsd.hoomd
with gsd.fl.open(name=sys.argv[1], mode='rb') as f:
    assert f.nframes == 401, f.nframes
    for frame in range(1, 401):
        step = f.read_chunk(frame=frame, name='configuration/step')
        assert step[0] == 1000 * (frame + 1), (frame, step)
        who = 'python/a' if (frame - 1) % 200 < 100 else 'kairos/another'
        name = 'extra/%s_fairly_long_quantity_name_%d' % (who, frame % 40)
        data = f.read_chunk(frame=frame, name=name)
        assert data.dtype == np.int64 and list(data.ravel()) == [frame, -frame], (frame, data)
with gsd.hoomd.open(sys.argv[1], 'rb') as traj:
    assert len(traj) == 401
    assert traj[400].configuration.step == 401000
    assert traj[400].particles.types == ['A', 'BB']
print('ok')
)PY";
  EXPECT_PYTHON_OK(python(check, {file("mixed.gsd")}));

  const Reader r(file("mixed.gsd"));
  ASSERT_EQ(r.frame_count(), 401u);
  for (std::uint64_t frame = 1; frame < 401; ++frame) {
    const auto f = static_cast<std::int64_t>(frame);
    const std::string who =
        (frame - 1) % 200 < 100 ? "extra/python/a_fairly_long_quantity_name_" : name_prefix;
    ASSERT_EQ(r.read<std::int64_t>(frame, who + std::to_string(frame % 40)),
              (std::vector<std::int64_t>{f, -f}))
        << frame;
    ASSERT_EQ(r.read<std::uint64_t>(frame, "configuration/step"),
              std::vector<std::uint64_t>{1000 * (frame + 1)});
  }
}

// Python writes every type over two frames (plus a HOOMD trajectory); we read and append.
TEST_F(GsdInterop, WeReadPythonFiles) {
  const char* const write = R"PY(
import sys
import numpy as np
import gsd.fl, gsd.hoomd
types = ['uint8', 'uint16', 'uint32', 'uint64', 'int8', 'int16', 'int32', 'int64',
         'float32', 'float64']
with gsd.fl.open(name=sys.argv[1], mode='wb', application='python-test', schema='hoomd',
                 schema_version=[1, 4]) as f:
    for frame in range(2):
        for i, t in enumerate(types):
            n, m = i % 3 + 1, i % 4 + 1
            data = (np.arange(n * m) * 3 + frame).astype(t).reshape(n, m)
            if frame == 0:
                data.flat[0] = np.iinfo(t).max if t[0] in 'ui' else np.finfo(t).max
            f.write_chunk(name='values/' + t, data=data)
        if frame == 0:
            f.write_chunk(name='empty', data=np.zeros((0, 3), np.float32))
        f.end_frame()
s = gsd.hoomd.Snapshot()
s.configuration.step = 77
s.configuration.box = [5, 6, 7, 0, 0, 0]
s.particles.N = 3
s.particles.types = ['A', 'Bc']
s.particles.typeid = [0, 1, 1]
s.particles.position = [[0, 0.5, 1], [1, 1.5, 2], [2, 2.5, 3]]
with gsd.hoomd.open(sys.argv[2], 'wb') as traj:
    traj.append(s)
)PY";
  ASSERT_EQ(python(write, {file("py.gsd"), file("pyhoomd.gsd")}).status, 0);

  {
    const Reader r(file("py.gsd"));
    EXPECT_EQ(r.application(), "python-test");
    EXPECT_EQ(r.schema(), "hoomd");
    EXPECT_EQ(r.schema_version(), (1u << 16) | 4u);
    ASSERT_EQ(r.frame_count(), 2u);
    const auto check = [&](auto zero, const std::string& type, std::size_t i) {
      using T = decltype(zero);
      for (std::uint64_t frame = 0; frame < 2; ++frame) {
        const std::string name = "values/" + type;
        const auto info = r.find(frame, name);
        ASSERT_TRUE(info) << name;
        EXPECT_EQ(info->type, type_of<T>()) << name;
        EXPECT_EQ(info->N, i % 3 + 1) << name;
        EXPECT_EQ(info->M, i % 4 + 1) << name;
        const auto values = r.read<T>(frame, name);
        ASSERT_EQ(values.size(), (i % 3 + 1) * (i % 4 + 1)) << name;
        for (std::size_t j = 0; j < values.size(); ++j) {
          const T expected =
              frame == 0 && j == 0 ? std::numeric_limits<T>::max() : static_cast<T>(3 * j + frame);
          EXPECT_EQ(values[j], expected) << name << "[" << j << "] frame " << frame;
        }
      }
    };
    check(std::uint8_t{}, "uint8", 0);
    check(std::uint16_t{}, "uint16", 1);
    check(std::uint32_t{}, "uint32", 2);
    check(std::uint64_t{}, "uint64", 3);
    check(std::int8_t{}, "int8", 4);
    check(std::int16_t{}, "int16", 5);
    check(std::int32_t{}, "int32", 6);
    check(std::int64_t{}, "int64", 7);
    check(float{}, "float32", 8);
    check(double{}, "float64", 9);
    const auto empty = r.find(0, "empty");
    ASSERT_TRUE(empty);
    EXPECT_EQ(empty->N, 0u);
    EXPECT_EQ(empty->M, 3u);
    EXPECT_TRUE(r.read<float>(0, "empty").empty());
    EXPECT_FALSE(r.find(1, "empty"));
  }
  {
    const Reader r(file("pyhoomd.gsd"));
    ASSERT_EQ(r.frame_count(), 1u);
    EXPECT_EQ(r.read<std::uint64_t>(0, "configuration/step"), std::vector<std::uint64_t>{77});
    EXPECT_EQ(r.read<float>(0, "configuration/box"), (std::vector<float>{5, 6, 7, 0, 0, 0}));
    EXPECT_EQ(r.read<std::uint32_t>(0, "particles/N"), std::vector<std::uint32_t>{3});
    EXPECT_EQ(r.read<std::uint32_t>(0, "particles/typeid"), (std::vector<std::uint32_t>{0, 1, 1}));
    EXPECT_EQ(r.read<float>(0, "particles/position"),
              (std::vector<float>{0, 0.5f, 1, 1, 1.5f, 2, 2, 2.5f, 3}));
    const auto types = r.find(0, "particles/types");
    ASSERT_TRUE(types);
    EXPECT_EQ(types->N, 2u);
    EXPECT_EQ(types->M, 3u);
    EXPECT_EQ(r.read<std::int8_t>(0, "particles/types"),
              (std::vector<std::int8_t>{'A', 0, 0, 'B', 'c', 0}));
  }

  // Append to the Python file; Python and we read the result.
  {
    auto w = Writer::open_append(file("py.gsd"));
    ASSERT_EQ(w.frame_count(), 2u);
    const std::uint16_t v[2] = {7, 9};
    w.write_chunk("values/uint16", 2, 1, v);
    w.write_chunk("kairos/new", 2, 1, v);
    w.end_frame();
  }
  const char* const check = R"PY(
import sys
import numpy as np
import gsd.fl
with gsd.fl.open(name=sys.argv[1], mode='rb') as f:
    assert f.nframes == 3, f.nframes
    assert list(f.read_chunk(frame=1, name='values/int32').ravel()) == [1, 4, 7]
    for name in ('values/uint16', 'kairos/new'):
        d = f.read_chunk(frame=2, name=name)
        assert d.dtype == np.uint16 and d.shape == (2,) and list(d) == [7, 9], d
    assert not f.chunk_exists(frame=2, name='values/int8')
print('ok')
)PY";
  EXPECT_PYTHON_OK(python(check, {file("py.gsd")}));
  const Reader r(file("py.gsd"));
  EXPECT_EQ(r.frame_count(), 3u);
  EXPECT_EQ(r.read<std::uint16_t>(2, "kairos/new"), (std::vector<std::uint16_t>{7, 9}));
}

// A file whose last frame was cut short: python-gsd and we agree after we append to it.
TEST_F(GsdInterop, PythonReadsAFileRepairedByAppending) {
  {
    auto w = Writer::create(file("cut.gsd"), "kairos-test");
    for (std::uint64_t f = 0; f < 3; ++f) write_hoomd_frame(w, f, f == 0);
  }
  fs::resize_file(file("cut.gsd"), fs::file_size(file("cut.gsd")) - 4);  // inside log/time
  {
    auto w = Writer::open_append(file("cut.gsd"));
    ASSERT_EQ(w.frame_count(), 2u);
    write_hoomd_frame(w, 2, false);
  }
  EXPECT_PYTHON_OK(python(kCheckHoomd, {file("cut.gsd"), "3"}));
}

// Bonds of chains in a Kairos trajectory (frame 0 only, inherited by later frames) and in a
// restart file, as python-gsd's HOOMD reader sees them.
TEST_F(GsdInterop, PythonReadsOurBonds) {
  kairos::SystemConfig sys;
  sys.particles = 40;
  sys.packing_fraction = 0.1;
  sys.chain_length = 4;
  std::mt19937_64 rng(1);
  ParticleSystem<3> s = kairos::to_particle_system<3>(kairos::make_initial_state<3>(sys, rng));
  s.events.assign(s.size(), kairos::EventSlot{});
  s.cell.assign(s.size(), 0);
  s.collision_count.assign(s.size(), 0);
  s.bond_types.push_back("spare");
  s.bonds[1].type = 1;                      // (1, 2) of chain 0
  for (auto& k : s.kinematics) k.vel = {};  // bond lengths stay 1 in every frame
  {
    auto w = Writer::create(file("chains.gsd"), "kairos-test");
    kairos::append_trajectory_frame<3>(w, s);
    s.time = 0.5;
    kairos::append_trajectory_frame<3>(w, s);
  }
  kairos::write_restart<3>(file("restart.gsd"), s, rng);
  const char* const check = R"PY(
import sys
import numpy as np
import gsd.hoomd
expected = np.array([[4 * c + k, 4 * c + k + 1] for c in range(10) for k in range(3)])
for name, nframes in ((sys.argv[1], 2), (sys.argv[2], 1)):
    with gsd.hoomd.open(name, 'rb') as traj:
        assert len(traj) == nframes, len(traj)
        for s in traj:
            assert s.bonds.N == 30, s.bonds.N
            assert s.bonds.types == ['backbone', 'spare'], s.bonds.types
            np.testing.assert_array_equal(s.bonds.group, expected)
            typeid = np.zeros(30, np.uint32)
            typeid[1] = 1
            np.testing.assert_array_equal(s.bonds.typeid, typeid)
            assert s.bonds.group.dtype == np.uint32 and s.bonds.typeid.dtype == np.uint32
            p = s.particles.position
            d = np.linalg.norm(p[expected[:, 0]] - p[expected[:, 1]], axis=1)
            assert np.all(np.abs(d - 1) < 1e-5), d
print('ok')
)PY";
  EXPECT_PYTHON_OK(python(check, {file("chains.gsd"), file("restart.gsd")}));
}

}  // namespace

#include "io/gsd_file.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "special_files.hpp"

namespace fs = std::filesystem;
using kairos::InputError;
using namespace kairos::gsd;

namespace {

class GsdFile : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("kairos_gsd_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path file(const std::string& name) const { return dir_ / name; }

  fs::path dir_;
};

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void spit(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

template <class T>
void put(std::string& bytes, std::size_t offset, T value) {
  std::memcpy(bytes.data() + offset, &value, sizeof value);
}

template <class T>
T get(const std::string& bytes, std::size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof value);
  return value;
}

template <class T>
std::vector<T> sample(std::size_t n) {
  std::vector<T> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<T>(i * 7 + 1);
  if (n > 0) v[0] = std::numeric_limits<T>::max();
  if (n > 1) v[1] = std::numeric_limits<T>::lowest();
  return v;
}

template <class T>
void write_sample(Writer& w, const std::string& name, std::uint64_t N, std::uint32_t M) {
  const auto v = sample<T>(N * M);
  w.write_chunk(name, N, M, v.data());
}

template <class T>
void expect_sample(const Reader& r, std::uint64_t frame, const std::string& name, std::uint64_t N,
                   std::uint32_t M) {
  const auto info = r.find(frame, name);
  ASSERT_TRUE(info) << name;
  EXPECT_EQ(info->type, type_of<T>()) << name;
  EXPECT_EQ(info->N, N) << name;
  EXPECT_EQ(info->M, M) << name;
  EXPECT_EQ(r.read<T>(frame, name), sample<T>(N * M)) << name;
}

// A three-frame file: per-frame step, a position array whose length varies, a frame-0-only chunk.
void write_frames(Writer& w, std::uint64_t first, std::uint64_t count) {
  for (std::uint64_t f = first; f < first + count; ++f) {
    const std::uint64_t step = 100 * f;
    w.write_chunk("configuration/step", 1, 1, &step);
    std::vector<float> pos(3 * (f + 1));
    for (std::size_t i = 0; i < pos.size(); ++i)
      pos[i] = static_cast<float>(f) + 0.5f * static_cast<float>(i);
    w.write_chunk("particles/position", f + 1, 3, pos.data());
    if (f == 0) write_sample<std::int8_t>(w, "particles/types", 2, 2);
    w.end_frame();
  }
}

void expect_frames(const Reader& r, std::uint64_t count) {
  ASSERT_EQ(r.frame_count(), count);
  for (std::uint64_t f = 0; f < count; ++f) {
    EXPECT_EQ(r.read<std::uint64_t>(f, "configuration/step"), std::vector<std::uint64_t>{100 * f});
    const auto pos = r.read<float>(f, "particles/position");
    ASSERT_EQ(pos.size(), 3 * (f + 1));
    for (std::size_t i = 0; i < pos.size(); ++i)
      EXPECT_EQ(pos[i], static_cast<float>(f) + 0.5f * static_cast<float>(i));
    EXPECT_EQ(r.find(f, "particles/types").has_value(), f == 0);
  }
}

TEST_F(GsdFile, RoundTripsEveryWritableType) {
  {
    auto w = Writer::create(file("t.gsd"), "kairos-test", "hoomd", (1u << 16) | 4u);
    write_sample<std::uint8_t>(w, "u8", 5, 1);
    write_sample<std::uint16_t>(w, "u16", 2, 3);
    write_sample<std::uint32_t>(w, "u32", 4, 2);
    write_sample<std::uint64_t>(w, "u64", 1, 1);
    write_sample<std::int8_t>(w, "i8", 3, 4);
    write_sample<std::int16_t>(w, "i16", 7, 1);
    write_sample<std::int32_t>(w, "i32", 2, 2);
    write_sample<std::int64_t>(w, "i64", 3, 1);
    write_sample<float>(w, "f32", 10, 3);
    write_sample<double>(w, "f64", 6, 4);
    w.write_chunk<double>("empty", 0, 3, nullptr);
    w.end_frame();
    EXPECT_EQ(w.frame_count(), 1u);
  }
  const Reader r(file("t.gsd"));
  EXPECT_EQ(r.application(), "kairos-test");
  EXPECT_EQ(r.schema(), "hoomd");
  EXPECT_EQ(r.schema_version(), (1u << 16) | 4u);
  ASSERT_EQ(r.frame_count(), 1u);
  expect_sample<std::uint8_t>(r, 0, "u8", 5, 1);
  expect_sample<std::uint16_t>(r, 0, "u16", 2, 3);
  expect_sample<std::uint32_t>(r, 0, "u32", 4, 2);
  expect_sample<std::uint64_t>(r, 0, "u64", 1, 1);
  expect_sample<std::int8_t>(r, 0, "i8", 3, 4);
  expect_sample<std::int16_t>(r, 0, "i16", 7, 1);
  expect_sample<std::int32_t>(r, 0, "i32", 2, 2);
  expect_sample<std::int64_t>(r, 0, "i64", 3, 1);
  expect_sample<float>(r, 0, "f32", 10, 3);
  expect_sample<double>(r, 0, "f64", 6, 4);
  expect_sample<double>(r, 0, "empty", 0, 3);
  EXPECT_EQ(r.chunk_names(), (std::vector<std::string>{"u8", "u16", "u32", "u64", "i8", "i16",
                                                       "i32", "i64", "f32", "f64", "empty"}));
}

TEST_F(GsdFile, TypeTable) {
  EXPECT_EQ(type_of<std::uint8_t>(), Type::uint8);
  EXPECT_EQ(type_of<std::int8_t>(), Type::int8);
  EXPECT_EQ(type_of<char>(), Type::character);
  EXPECT_EQ(type_of<double>(), Type::float64);
  EXPECT_EQ(static_cast<int>(Type::float64), 10);
  EXPECT_EQ(type_size(Type::uint16), 2u);
  EXPECT_EQ(type_size(Type::int64), 8u);
  EXPECT_EQ(type_size(Type::float32), 4u);
  EXPECT_EQ(type_size(Type::character), 1u);
  EXPECT_EQ(type_size(static_cast<Type>(0)), 0u);
  EXPECT_EQ(type_size(static_cast<Type>(12)), 0u);
}

// The Writer refuses type character (python-gsd 2.7 calls such files corrupt), but the Reader
// reads it: store a uint8 chunk and patch its index entry's type byte to 11.
TEST_F(GsdFile, ReadsCharacterChunks) {
  const std::string text = "hello, gsd";
  {
    auto w = Writer::create(file("c.gsd"), "test");
    EXPECT_THROW(w.write_chunk("text", Type::character, 1, 1, "x"), std::invalid_argument);
    w.write_chunk("text", text.size(), 1, reinterpret_cast<const std::uint8_t*>(text.data()));
    w.end_frame();
  }
  std::string bytes = slurp(file("c.gsd"));
  const auto index = get<std::uint64_t>(bytes, 8);
  ASSERT_EQ(static_cast<unsigned char>(bytes[index + 30]), 1u);  // entry 0: type uint8
  bytes[index + 30] = 11;
  spit(file("c.gsd"), bytes);
  const Reader r(file("c.gsd"));
  const auto chars = r.read<char>(0, "text");
  EXPECT_EQ(std::string(chars.begin(), chars.end()), text);
}

TEST_F(GsdFile, MultipleFrames) {
  {
    auto w = Writer::create(file("m.gsd"), "test");
    write_frames(w, 0, 3);
    EXPECT_EQ(w.frame_count(), 3u);
  }
  const Reader r(file("m.gsd"));
  expect_frames(r, 3);
  EXPECT_EQ(r.chunk_names(), (std::vector<std::string>{"configuration/step", "particles/position",
                                                       "particles/types"}));
}

TEST_F(GsdFile, AppendsAfterReopen) {
  {
    auto w = Writer::create(file("a.gsd"), "test");
    write_frames(w, 0, 2);
  }
  {
    auto w = Writer::open_append(file("a.gsd"));
    EXPECT_EQ(w.frame_count(), 2u);
    write_frames(w, 2, 2);
    const std::uint32_t extra = 42;
    w.write_chunk("log/extra", 1, 1, &extra);
    const std::uint64_t step = 400;
    w.write_chunk("configuration/step", 1, 1, &step);
    std::vector<float> pos(15);
    for (std::size_t i = 0; i < pos.size(); ++i) pos[i] = 4.0f + 0.5f * static_cast<float>(i);
    w.write_chunk("particles/position", 5, 3, pos.data());
    w.end_frame();
    EXPECT_EQ(w.frame_count(), 5u);
  }
  const Reader r(file("a.gsd"));
  expect_frames(r, 5);
  EXPECT_EQ(r.read<std::uint32_t>(4, "log/extra"), std::vector<std::uint32_t>{42});
  EXPECT_FALSE(r.find(3, "log/extra"));
}

// Enough frames and names to move the index and the namelist several times, with reopening.
TEST_F(GsdFile, GrowsIndexAndNamelist) {
  const auto name = [](int i) { return "log/some/rather/long/quantity/name/" + std::to_string(i); };
  for (int round = 0; round < 3; ++round) {
    auto w =
        round == 0 ? Writer::create(file("g.gsd"), "test") : Writer::open_append(file("g.gsd"));
    for (int f = 0; f < 150; ++f) {
      const int frame = round * 150 + f;
      for (int c = 0; c <= frame % 7; ++c) {
        const std::int32_t value[2] = {frame, c};
        w.write_chunk(name(c + frame / 10), 1, 2, value);
      }
      w.end_frame();
    }
  }
  const Reader r(file("g.gsd"));
  ASSERT_EQ(r.frame_count(), 450u);
  EXPECT_EQ(r.chunk_names().size(), 45u + 6u);
  for (int frame = 0; frame < 450; ++frame) {
    for (int c = 0; c <= frame % 7; ++c)
      ASSERT_EQ(r.read<std::int32_t>(frame, name(c + frame / 10)),
                (std::vector<std::int32_t>{frame, c}));
    EXPECT_FALSE(r.find(frame, name(frame / 10 + 7)));
  }
}

TEST_F(GsdFile, LargeChunksBypassTheBuffer) {
  std::vector<double> big(3'000'000);
  for (std::size_t i = 0; i < big.size(); ++i) big[i] = 0.25 * static_cast<double>(i);
  {
    auto w = Writer::create(file("b.gsd"), "test");
    for (int f = 0; f < 2; ++f) {
      const std::uint8_t small = static_cast<std::uint8_t>(f);
      w.write_chunk("small", 1, 1, &small);
      w.write_chunk("big", big.size() / 3, 3, big.data());
      w.write_chunk("after", 1, 1, &small);
      w.end_frame();
    }
  }
  const Reader r(file("b.gsd"));
  ASSERT_EQ(r.frame_count(), 2u);
  EXPECT_EQ(r.read<double>(1, "big"), big);
  EXPECT_EQ(r.read<std::uint8_t>(1, "after"), std::vector<std::uint8_t>{1});
}

TEST_F(GsdFile, FindReportsAbsentChunks) {
  {
    auto w = Writer::create(file("f.gsd"), "test");
    write_frames(w, 0, 2);
  }
  const Reader r(file("f.gsd"));
  EXPECT_FALSE(r.find(0, "particles/velocity"));
  EXPECT_FALSE(r.find(1, "particles/types"));
  EXPECT_FALSE(r.find(2, "configuration/step"));
  EXPECT_TRUE(r.find(1, "configuration/step"));
  try {
    (void)r.read<float>(1, "particles/types");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("particles/types"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("f.gsd"), std::string::npos) << e.what();
  }
}

TEST_F(GsdFile, TypeMismatchIsAnInputError) {
  {
    auto w = Writer::create(file("m.gsd"), "test");
    write_frames(w, 0, 1);
  }
  const Reader r(file("m.gsd"));
  try {
    (void)r.read<double>(0, "particles/position");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("particles/position"), std::string::npos) << what;
    EXPECT_NE(what.find("float32"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  EXPECT_THROW((void)r.read<std::int8_t>(0, "configuration/step"), InputError);
}

TEST_F(GsdFile, MissingFileIsAnInputError) {
  EXPECT_THROW(Reader{file("nope.gsd")}, InputError);
  EXPECT_THROW(Writer::open_append(file("nope.gsd")), InputError);
  EXPECT_THROW(Writer::create(file("no/such/dir.gsd"), "test"), InputError);
}

// A FIFO, a directory or a device is refused at once: opening a FIFO for reading would wait
// for a writer forever.
TEST_F(GsdFile, SpecialFilesAreRefusedWithoutBlocking) {
  kairos::testing::make_fifo(file("fifo.gsd"));
  fs::create_directories(file("dir.gsd"));
  const std::pair<fs::path, std::string> cases[] = {{file("fifo.gsd"), "a FIFO"},
                                                    {file("dir.gsd"), "a directory"},
                                                    {"/dev/null", "a character device"}};
  for (const auto& [path, kind] : cases) {
    std::string expected = "'";  // (not "'" + ...: a GCC 12 -Wrestrict false positive)
    expected += path.string();
    expected += "' is not a regular file (it is " + kind + ")";
    for (const bool append : {false, true}) {
      const std::string message = kairos::testing::refusal_without_blocking(path, [&] {
        if (append)
          (void)Writer::open_append(path);
        else
          (void)Reader{path};
      });
      EXPECT_NE(message.find(expected), std::string::npos) << message;
    }
  }
}

TEST_F(GsdFile, GarbageAndDamagedHeadersAreInputErrors) {
  {
    auto w = Writer::create(file("good.gsd"), "test");
    write_frames(w, 0, 2);
  }
  const std::string good = slurp(file("good.gsd"));
  std::vector<std::string> bad;
  bad.push_back("");
  bad.push_back(good.substr(0, 100));    // truncated header
  bad.push_back(good.substr(0, 300));    // index and namelist cut off
  const std::string garbage(6000, 'x');  // a named copy: GCC 12 misreads a moved temporary
  bad.push_back(garbage);
  std::string s = good;
  put<std::uint32_t>(s, 44, 1u << 16);  // gsd version 1.0
  bad.push_back(s);
  s = good;
  put<std::uint32_t>(s, 44, 3u << 16);  // gsd version 3.0
  bad.push_back(s);
  s = good;
  put<std::uint64_t>(s, 8, std::uint64_t{1} << 62);  // index location
  bad.push_back(s);
  s = good;
  put<std::uint64_t>(s, 16, std::uint64_t{1} << 60);  // index size
  bad.push_back(s);
  s = good;
  put<std::uint64_t>(s, 32, ~std::uint64_t{0});  // namelist size
  bad.push_back(s);
  s = good;
  const auto namelist = get<std::uint64_t>(good, 24);
  std::memset(s.data() + namelist, 'n', 1024);  // unterminated names
  bad.push_back(s);
  for (std::size_t i = 0; i < bad.size(); ++i) {
    spit(file("bad.gsd"), bad[i]);
    EXPECT_THROW(Reader{file("bad.gsd")}, InputError) << "case " << i;
    EXPECT_THROW(Writer::open_append(file("bad.gsd")), InputError) << "case " << i;
  }
  spit(file("bad.gsd"), bad[3]);
  try {
    Reader{file("bad.gsd")};
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.gsd"), std::string::npos) << e.what();
  }
}

// Corrupt index entries (bad type, name id, flags) end the index: their frame is dropped.
TEST_F(GsdFile, CorruptIndexEntryDropsItsFrame) {
  {
    auto w = Writer::create(file("e.gsd"), "test");
    write_frames(w, 0, 3);
  }
  const std::string good = slurp(file("e.gsd"));
  const auto index = get<std::uint64_t>(good, 8);
  const std::size_t entry = index + 32 * 5;  // frame 2's first entry (3 + 2 before it)
  ASSERT_EQ(get<std::uint64_t>(good, entry), 2u);
  for (const std::size_t field : {entry + 28, entry + 30, entry + 31}) {
    std::string s = good;
    s[field] = static_cast<char>(0x7F);
    spit(file("e.gsd"), s);
    const Reader r(file("e.gsd"));
    expect_frames(r, 2);
  }
}

// An entry that claims more data than the file holds, or is otherwise invalid, followed by intact
// later frames is damage, not an interrupted write: an InputError naming the file and the chunk
// (reading on would silently lose every later frame).
TEST_F(GsdFile, DamagedEntryBeforeIntactFramesIsAnInputError) {
  {
    auto w = Writer::create(file("m.gsd"), "test");
    write_frames(w, 0, 3);
  }
  const std::string good = slurp(file("m.gsd"));
  const auto index = get<std::uint64_t>(good, 8);
  const std::size_t entry = index + 32 * 1;  // frame 0's particles/position
  ASSERT_EQ(get<std::uint64_t>(good, entry), 0u);
  ASSERT_EQ(get<std::uint64_t>(good, entry + 8), 1u);
  std::string huge = good;
  put<std::uint64_t>(huge, entry + 8, 50'000'000);  // N
  std::string bad_type = good;
  bad_type[entry + 30] = static_cast<char>(0x7F);
  for (const std::string& damaged : {huge, bad_type}) {
    spit(file("m.gsd"), damaged);
    for (const bool append : {false, true}) {
      try {
        if (append)
          (void)Writer::open_append(file("m.gsd"));
        else
          (void)Reader{file("m.gsd")};
        ADD_FAILURE() << "a damaged entry before intact frames was accepted";
      } catch (const InputError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(file("m.gsd").string()), std::string::npos) << message;
        EXPECT_NE(message.find("chunk 'particles/position' in frame 0"), std::string::npos)
            << message;
      }
    }
  }
  spit(file("m.gsd"), huge);
  try {
    (void)Reader{file("m.gsd")};
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("50000000 x 3 float32 values"), std::string::npos)
        << e.what();
  }
}

// The same claim in the last frame is a truncated tail (the commit protocol): that frame is
// dropped, the others read, and nothing is allocated for the claim.
TEST_F(GsdFile, HugeEntryInTheLastFrameEndsTheIndex) {
  {
    auto w = Writer::create(file("h.gsd"), "test");
    write_frames(w, 0, 3);
  }
  std::string s = slurp(file("h.gsd"));
  const std::size_t entry = get<std::uint64_t>(s, 8) + 32 * 6;  // frame 2's particles/position
  ASSERT_EQ(get<std::uint64_t>(s, entry), 2u);
  put<std::uint64_t>(s, entry + 8, std::uint64_t{1} << 60);
  spit(file("h.gsd"), s);
  expect_frames(Reader(file("h.gsd")), 2);
}

// CRC-32 (IEEE, reflected, as zlib, zip and PNG compute it) bit by bit: an implementation
// independent of the library's.
std::uint32_t reference_crc32(const std::string& bytes) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (const char c : bytes) {
    crc ^= static_cast<unsigned char>(c);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

// One chunk as the frame checksum serialises it: name, 0, type, N (8 bytes), M (4 bytes), data.
template <class T>
std::string canonical(const std::string& name, std::uint64_t N, std::uint32_t M,
                      const std::vector<T>& values) {
  std::string out = name;
  out.push_back('\0');
  out.push_back(static_cast<char>(type_of<T>()));
  out.append(reinterpret_cast<const char*>(&N), 8);
  out.append(reinterpret_cast<const char*>(&M), 4);
  out.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
  return out;
}

// The frame checksum is the CRC-32 of the chunks' canonical serialisation in name order,
// whatever order they were written in; writer and reader agree, and the reader can leave out
// the chunk that stores it.
TEST_F(GsdFile, FrameChecksumIsTheCrcOfTheCanonicalChunksInNameOrder) {
  const std::vector<double> b = {1.5, -2.0, 3.25, 4.0};
  const std::vector<std::uint8_t> a = {7};
  const std::vector<float> empty;
  const std::uint32_t expected =
      reference_crc32(canonical("a/one", 1, 1, a) + canonical("b/two", 2, 2, b) +
                      canonical("c/empty", 0, 3, empty));
  std::uint32_t written[2] = {};
  for (const bool reversed : {false, true}) {
    auto w = Writer::create(file("c.gsd"), "test");
    w.enable_checksums();
    if (reversed) {
      w.write_chunk("c/empty", 0, 3, empty.data());
      w.write_chunk("b/two", 2, 2, b.data());
      w.write_chunk("a/one", 1, 1, a.data());
    } else {
      w.write_chunk("a/one", 1, 1, a.data());
      w.write_chunk("b/two", 2, 2, b.data());
      w.write_chunk("c/empty", 0, 3, empty.data());
    }
    written[reversed] = w.frame_checksum();
    w.write_chunk("z/checksum", 1, 1, &written[reversed]);
    w.end_frame();
    w.close();
    EXPECT_EQ(written[reversed], expected);
    const Reader r(file("c.gsd"));
    EXPECT_EQ(r.frame_checksum(0, "z/checksum"), expected);
    EXPECT_NE(r.frame_checksum(0, ""), expected);  // the checksum chunk itself counts then
  }
  auto w = Writer::create(file("d.gsd"), "test");
  EXPECT_THROW((void)w.frame_checksum(), std::logic_error);  // not enabled
}

// Random damage to the header, index or namelist: an InputError or readable data, never a crash.
TEST_F(GsdFile, RandomlyDamagedFilesNeverCrash) {
  {
    auto w = Writer::create(file("r.gsd"), "test");
    write_frames(w, 0, 3);
  }
  const std::string good = slurp(file("r.gsd"));
  const std::size_t metadata = 256 + 128 * 32 + 1024;
  std::mt19937 rng(12345);
  for (int trial = 0; trial < 300; ++trial) {
    std::string s = good;
    for (int k = 0; k <= trial % 4; ++k) s[rng() % metadata] = static_cast<char>(rng() % 256);
    spit(file("bad.gsd"), s);
    try {
      const Reader r(file("bad.gsd"));
      for (std::uint64_t f = 0; f < r.frame_count(); ++f)
        for (const auto& name : r.chunk_names()) {
          const auto read = [&](auto zero) {
            try {
              (void)r.read<decltype(zero)>(f, name);
            } catch (const InputError&) {
            }
          };
          read(float{});
          read(std::uint64_t{});
          read(std::int8_t{});
        }
    } catch (const InputError&) {
    }
  }
}

// The process dies while a frame is being written: the data is partly on disk but no index
// entry refers to it. The earlier frames read, and appending continues after them.
TEST_F(GsdFile, FrameInterruptedByProcessDeathIsAbsent) {
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    try {
      auto w = Writer::create(file("k.gsd"), "test");
      write_frames(w, 0, 2);
      const std::vector<double> big(1'000'000, 1.0);  // larger than the buffer: reaches the disk
      const std::uint64_t step = 999;
      w.write_chunk("configuration/step", 1, 1, &step);
      w.write_chunk("particles/velocity", big.size(), 1, big.data());
      std::_Exit(0);  // no destructors, no end_frame
    } catch (...) {
      std::_Exit(1);
    }
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  EXPECT_GT(fs::file_size(file("k.gsd")), 8'000'000u);
  {
    const Reader r(file("k.gsd"));
    expect_frames(r, 2);
    EXPECT_FALSE(r.find(2, "particles/velocity"));
  }
  {
    auto w = Writer::open_append(file("k.gsd"));
    EXPECT_EQ(w.frame_count(), 2u);
    write_frames(w, 2, 1);
  }
  expect_frames(Reader(file("k.gsd")), 3);
}

// Destroying a writer mid-frame (e.g. during stack unwinding) discards the frame.
TEST_F(GsdFile, UnendedFrameIsDiscardedByTheDestructor) {
  std::uintmax_t committed = 0;
  {
    auto w = Writer::create(file("u.gsd"), "test");
    write_frames(w, 0, 2);
    committed = fs::file_size(file("u.gsd"));
    const std::vector<float> big(2'000'000, 2.0f);
    w.write_chunk("particles/velocity", big.size() / 2, 2, big.data());
  }
  EXPECT_EQ(fs::file_size(file("u.gsd")), committed);
  expect_frames(Reader(file("u.gsd")), 2);
}

// A file cut inside its last frame's data (e.g. copied while being written, or a full disk):
// that frame is dropped, the earlier ones read, and appending replaces the lost frame.
TEST_F(GsdFile, TruncatedLastFrameIsDropped) {
  {
    auto w = Writer::create(file("t.gsd"), "test");
    write_frames(w, 0, 3);
  }
  fs::resize_file(file("t.gsd"), fs::file_size(file("t.gsd")) - 4);
  {
    const Reader r(file("t.gsd"));
    expect_frames(r, 2);
  }
  {
    auto w = Writer::open_append(file("t.gsd"));
    EXPECT_EQ(w.frame_count(), 2u);
    write_frames(w, 2, 2);
  }
  expect_frames(Reader(file("t.gsd")), 4);
}

TEST_F(GsdFile, WriterMisuse) {
  auto w = Writer::create(file("x.gsd"), "test");
  const std::uint32_t v = 1;
  w.write_chunk("a", 1, 1, &v);
  EXPECT_THROW(w.write_chunk("a", 1, 1, &v), std::invalid_argument);
  EXPECT_THROW(w.write_chunk("", 1, 1, &v), std::invalid_argument);
  EXPECT_THROW(w.write_chunk<std::uint32_t>("b", 1, 1, nullptr), std::invalid_argument);
  EXPECT_THROW(w.write_chunk("b", static_cast<Type>(0), 1, 1, &v), std::invalid_argument);
  EXPECT_THROW(Writer::create(file("y.gsd"), std::string(64, 'a')), std::invalid_argument);
  w.end_frame();
  Writer moved = std::move(w);
  moved.write_chunk("a", 1, 1, &v);
  moved.end_frame();
  EXPECT_EQ(moved.frame_count(), 2u);
  moved.close();
  EXPECT_THROW(moved.write_chunk("a", 1, 1, &v), std::logic_error);
  EXPECT_EQ(Reader(file("x.gsd")).frame_count(), 2u);
}

TEST_F(GsdFile, EmptyFileHasNoFrames) {
  { auto w = Writer::create(file("n.gsd"), "test"); }
  const Reader r(file("n.gsd"));
  EXPECT_EQ(r.frame_count(), 0u);
  EXPECT_TRUE(r.chunk_names().empty());
  EXPECT_FALSE(r.find(0, "configuration/step"));
}

}  // namespace

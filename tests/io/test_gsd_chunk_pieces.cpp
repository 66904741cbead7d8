// A GSD chunk written in pieces (Writer::begin_chunk, append_to_chunk, end_chunk) is the chunk
// written whole: the same file bytes and frame checksum, and a wrong amount of data is refused.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/gsd_file.hpp"

namespace fs = std::filesystem;
using namespace kairos::gsd;

namespace {

fs::path temp(const std::string& name) {
  return fs::temp_directory_path() / ("kairos_pieces_" + std::to_string(::getpid()) + "_" + name);
}

std::string bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Values larger than the writer's 4 MiB buffer, so that pieces go both through the buffer and
// straight to the file.
std::vector<double> values(std::size_t n) {
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = 0.5 * static_cast<double>(i) - 1e3;
  return v;
}

}  // namespace

TEST(GsdChunkPieces, SameBytesAndChecksumAsOneWrite) {
  const std::vector<double> v = values(3 * 700001);  // 16.8 MB
  const std::uint32_t small[3] = {7, 8, 9};
  const fs::path whole = temp("whole.gsd"), pieces = temp("pieces.gsd");
  std::uint32_t crc_whole = 0, crc_pieces = 0;
  {
    auto w = Writer::create(whole, "test");
    w.enable_checksums();
    w.write_chunk("a/small", 3, 1, small);
    w.write_chunk("b/values", v.size() / 3, 3, v.data());
    crc_whole = w.frame_checksum();
    w.write_chunk("c/crc", 1, 1, &crc_whole);
    w.end_frame();
  }
  {
    auto w = Writer::create(pieces, "test");
    w.enable_checksums();
    w.write_chunk("a/small", 3, 1, small);
    w.begin_chunk("b/values", Type::float64, v.size() / 3, 3);
    // Uneven pieces: a few values, then 1 MB, then more than the buffer, then the rest.
    const std::size_t cuts[] = {0, 5, 131072 + 5, 131072 + 5 + 600000, v.size()};
    for (int k = 0; k + 1 < 5; ++k)
      w.append_to_chunk(v.data() + cuts[k], (cuts[k + 1] - cuts[k]) * sizeof(double));
    w.end_chunk();
    crc_pieces = w.frame_checksum();
    w.write_chunk("c/crc", 1, 1, &crc_pieces);
    w.end_frame();
  }
  EXPECT_EQ(crc_whole, crc_pieces);
  EXPECT_EQ(bytes_of(whole), bytes_of(pieces));
  const Reader r(pieces);
  EXPECT_EQ(r.frame_checksum(0, "c/crc"), crc_pieces);
  EXPECT_EQ(r.read<double>(0, "b/values"), v);
  fs::remove(whole);
  fs::remove(pieces);
}

TEST(GsdChunkPieces, WrongAmountsOfDataAreRefused) {
  const fs::path p = temp("wrong.gsd");
  auto w = Writer::create(p, "test");
  const double x[4] = {1, 2, 3, 4};
  w.begin_chunk("v", Type::float64, 3, 1);
  EXPECT_THROW(w.append_to_chunk(x, sizeof x), std::logic_error);  // 4 values for 3
  w.append_to_chunk(x, 2 * sizeof(double));
  EXPECT_THROW(w.end_chunk(), std::logic_error);                     // 2 of 3
  EXPECT_THROW(w.end_frame(), std::logic_error);                     // a chunk still open
  EXPECT_THROW(w.write_chunk("u", 1, 1, x), std::invalid_argument);  // another in between
  w.append_to_chunk(x + 2, sizeof(double));
  w.end_chunk();
  EXPECT_THROW(w.append_to_chunk(x, sizeof(double)), std::logic_error);  // none open
  w.end_frame();
  fs::remove(p);
}

// GSD (General Simulation Data, HOOMD-blue's trajectory format) file layer, written from the
// published file-layer specification, version 2.0 (https://gsd.readthedocs.io, "File layer").
// Files written here are GSD 2.0 files; files of any 2.x version are read.
//
// Layout (little-endian, byte offsets):
//   header    256 bytes at 0: u64 magic 0x65DF65DF65DF65DF, u64 index location, u64 index
//             capacity (entries), u64 namelist location, u64 namelist capacity (64-byte
//             segments), u32 schema version, u32 gsd version (0xMMMMmmmm), char application[64],
//             char schema[64], 80 reserved bytes.
//   index     capacity x 32-byte entries {u64 frame, u64 N, i64 location, u32 M, u16 name id,
//             u8 type, u8 flags = 0}, sorted by (frame, id); the first entry with location 0
//             ends the list. Frame count = last entry's frame + 1.
//   namelist  chunk names, each 0-terminated; an empty name ends the list; a name's id is its
//             position in the list.
//   data      each chunk's N x M values, row-major, at its entry's location.
//
// Commit protocol (Writer::end_frame): the frame's data, its new names (into the namelist's free
// space, or a doubled copy at the end of the file) and, when the index is full, a doubled copy of
// the index that already holds the frame's entries are written and fsync'ed. Only then does the
// frame become visible, by one write of its entries into free index slots or by one 256-byte
// header write pointing at the new index; fsync. A process killed before that leaves only
// unreferenced bytes at the end of the file. The Reader checks every index entry before anything
// is allocated for it (its N x M values must lie inside the file, as must the index and the
// namelist). An invalid entry (e.g. one pointing past the end of a truncated file) that no intact
// later frame follows is a torn or truncated tail: it ends the index and its frame is dropped.
// One that intact later frames follow cannot come from an interrupted write: an InputError
// naming the chunk.
//
// Frame checksums (Writer::enable_checksums, Writer::frame_checksum, Reader::frame_checksum): a
// CRC-32 (zlib's crc32, the CRC of zip and PNG) over a canonical serialisation of a frame's
// chunks, independent of the order they were written in and of their place in the file: the
// chunks in bytewise order of their names, each as its name, one 0 byte, its type (1 byte), N
// (8 bytes) and M (4 bytes, both little-endian), then its N x M values as stored.
//
// Type::character (added in spec 2.1) is readable, but the Writer refuses it: python-gsd 2.7
// reports a file holding such a chunk as corrupt. Store strings as int8 (as HOOMD does).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace kairos::gsd {

// clang-format off
enum class Type : std::uint8_t {
  uint8 = 1, uint16, uint32, uint64, int8, int16, int32, int64, float32, float64, character
};

template <class T> inline constexpr Type kTypeOf = Type{};  // Type{}: no GSD type
template <> inline constexpr Type kTypeOf<std::uint8_t> = Type::uint8;
template <> inline constexpr Type kTypeOf<std::uint16_t> = Type::uint16;
template <> inline constexpr Type kTypeOf<std::uint32_t> = Type::uint32;
template <> inline constexpr Type kTypeOf<std::uint64_t> = Type::uint64;
template <> inline constexpr Type kTypeOf<std::int8_t> = Type::int8;
template <> inline constexpr Type kTypeOf<std::int16_t> = Type::int16;
template <> inline constexpr Type kTypeOf<std::int32_t> = Type::int32;
template <> inline constexpr Type kTypeOf<std::int64_t> = Type::int64;
template <> inline constexpr Type kTypeOf<float> = Type::float32;
template <> inline constexpr Type kTypeOf<double> = Type::float64;
template <> inline constexpr Type kTypeOf<char> = Type::character;
// clang-format on

template <class T>
constexpr Type type_of() {
  static_assert(kTypeOf<T> != Type{}, "no GSD type for this C++ type");
  return kTypeOf<T>;
}

std::size_t type_size(Type type);  // bytes per element; 0 for a value outside the enum
std::string_view type_name(Type type);

// Appends frames to a GSD file. Move-only; the destructor closes the file and never throws.
// Chunks written since the last end_frame() belong to the frame being built; close() or the
// destructor discards them. Programming errors (bad name, duplicate chunk in a frame, character
// type, use after close) throw std::invalid_argument / std::logic_error; I/O errors InputError.
// After an I/O error in end_frame() the writer is closed (committed frames stay intact).
class Writer {
 public:
  // Creates (truncates) a file: schema "hoomd", schema_version 1.4 unless given.
  static Writer create(const std::filesystem::path& path, std::string_view application,
                       std::string_view schema = "hoomd",
                       std::uint32_t schema_version = (1u << 16) | 4u);
  // Opens an existing GSD 2.x file (a regular file) to append frames; InputError if it is not.
  // Frames from `keep_frames` on are dropped first (a run continued from an earlier state: the
  // frames it had written after that state), their bytes left unreferenced.
  static Writer open_append(const std::filesystem::path& path,
                            std::uint64_t keep_frames = ~std::uint64_t{0});

  Writer(Writer&&) noexcept;
  Writer& operator=(Writer&&) noexcept;
  ~Writer();

  template <class T>
  void write_chunk(std::string_view name, std::uint64_t N, std::uint32_t M, const T* data) {
    static_assert(type_of<T>() != Type::character, "GSD 2.0 has no character type; use int8");
    write_chunk(name, type_of<T>(), N, M, data);
  }
  // N x M values of `type` at `data` (may be null when N * M == 0).
  void write_chunk(std::string_view name, Type type, std::uint64_t N, std::uint32_t M,
                   const void* data);
  // A chunk written in pieces, so that its values never need to be in memory at once:
  // begin_chunk, then append_to_chunk until its N x M values were given (in order), then
  // end_chunk (logic_error if fewer or more bytes came). The file holds the same bytes as after
  // write_chunk of the whole; no other chunk may be written in between.
  void begin_chunk(std::string_view name, Type type, std::uint64_t N, std::uint32_t M);
  void append_to_chunk(const void* data, std::size_t bytes);
  void end_chunk();
  // From now on, keep the CRC-32 of each chunk written (see "Frame checksums" above), so that
  // frame_checksum() can be asked before end_frame(). Off by default: trajectories skip the cost.
  void enable_checksums();
  // The checksum of the chunks written so far in the frame being built (logic_error unless
  // enable_checksums() was called first). Write it as a chunk of the same frame, and verify it
  // with Reader::frame_checksum(frame, that chunk's name).
  std::uint32_t frame_checksum() const;
  // Commits the frame: on return it is durable on disk (data, namelist, index; fsync).
  // A frame without chunks has no index entry, so it persists only if a later frame has chunks.
  void end_frame();
  std::uint64_t frame_count() const;  // completed frames (including those found by open_append)
  void close() noexcept;

 private:
  struct State;
  explicit Writer(std::unique_ptr<State> state);
  State& state(const char* what) const;
  std::unique_ptr<State> s_;
};

// Reads a GSD 2.x file. The header, namelist and index are loaded at construction.
class Reader {
 public:
  // InputError if missing, not GSD 2.x, or not a regular file (a FIFO, directory or device is
  // refused at once: opening a FIFO would wait for a writer).
  explicit Reader(const std::filesystem::path& path);
  Reader(Reader&&) noexcept;
  Reader& operator=(Reader&&) noexcept;
  ~Reader();

  std::uint64_t frame_count() const;
  std::string application() const;
  std::string schema() const;
  std::uint32_t schema_version() const;  // 0xMMMMmmmm

  struct ChunkInfo {
    Type type;
    std::uint64_t N;
    std::uint32_t M;
  };
  std::optional<ChunkInfo> find(std::uint64_t frame, std::string_view name) const;
  // All N * M values, row-major. InputError if absent or stored with another type than T.
  template <class T>
  std::vector<T> read(std::uint64_t frame, std::string_view name) const {
    const Located chunk = locate(frame, name, type_of<T>());
    std::vector<T> values(chunk.count);
    read_bytes(chunk.location, values.data(), values.size() * sizeof(T));
    return values;
  }
  std::vector<std::string> chunk_names() const;  // all names in the namelist, in id order
  // The checksum (see "Frame checksums" above) of all chunks of `frame` but `except` (the chunk
  // that stores it); reads every chunk of the frame.
  std::uint32_t frame_checksum(std::uint64_t frame, std::string_view except) const;

 private:
  struct Located {
    std::uint64_t location;
    std::size_t count;
  };
  Located locate(std::uint64_t frame, std::string_view name, Type type) const;
  void read_bytes(std::uint64_t location, void* dst, std::size_t bytes) const;
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace kairos::gsd

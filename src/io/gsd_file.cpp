// GSD 2.0 file layer; the layout and the commit protocol are described in gsd_file.hpp.
#include "io/gsd_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <unordered_map>

#include <zlib.h>

#include "core/error.hpp"

namespace kairos::gsd {
namespace {

constexpr std::uint64_t kMagic = 0x65DF65DF65DF65DFull;
constexpr std::uint32_t kGsdVersion = 2u << 16;  // we write file layer 2.0
constexpr std::uint64_t kInitialIndex = 128;     // entries
constexpr std::uint64_t kInitialNamelist = 16;   // 64-byte segments
constexpr std::size_t kBufferBytes = 1u << 18;   // chunk data is written in pieces of 256 KiB

struct Header {
  std::uint64_t magic;
  std::uint64_t index_location;
  std::uint64_t index_allocated_entries;
  std::uint64_t namelist_location;
  std::uint64_t namelist_allocated_entries;  // 64-byte segments
  std::uint32_t schema_version;
  std::uint32_t gsd_version;
  char application[64];
  char schema[64];
  char reserved[80];
};

struct Entry {
  std::uint64_t frame;
  std::uint64_t N;
  std::int64_t location;
  std::uint32_t M;
  std::uint16_t id;
  std::uint8_t type;
  std::uint8_t flags;
};

static_assert(sizeof(Header) == 256 && sizeof(Entry) == 32);
static_assert(std::endian::native == std::endian::little, "GSD files are little-endian");

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what) {
  throw InputError("GSD file '" + path.string() + "': " + what);
}

class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  int get() const { return fd_; }

 private:
  int fd_;
};

// Reads up to `bytes`; returns the count read (short only at the end of the file).
std::size_t read_at(int fd, void* dst, std::size_t bytes, std::uint64_t offset,
                    const std::filesystem::path& path) {
  std::size_t done = 0;
  while (done < bytes) {
    const ssize_t n = ::pread(fd, static_cast<char*>(dst) + done, bytes - done,
                              static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail(path, std::string("read failed: ") + std::strerror(errno));
    if (n == 0) break;
    done += static_cast<std::size_t>(n);
  }
  return done;
}

void write_at(int fd, const void* src, std::size_t bytes, std::uint64_t offset,
              const std::filesystem::path& path) {
  std::size_t done = 0;
  while (done < bytes) {
    const ssize_t n = ::pwrite(fd, static_cast<const char*>(src) + done, bytes - done,
                               static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail(path, std::string("write failed: ") + std::strerror(errno));
    done += static_cast<std::size_t>(n);
  }
}

[[noreturn]] void not_regular(const std::filesystem::path& path, mode_t mode) {
  const char* kind = S_ISDIR(mode)    ? "a directory"
                     : S_ISFIFO(mode) ? "a FIFO"
                     : S_ISCHR(mode)  ? "a character device"
                     : S_ISBLK(mode)  ? "a block device"
                     : S_ISSOCK(mode) ? "a socket"
                                      : "a special file";
  throw InputError("'" + path.string() + "' is not a regular file (it is " + kind +
                   "): give the path of a GSD file");
}

// Opens an existing GSD file. Only regular files: opening a FIFO would block until some other
// process writes to it, and a device or directory is never a GSD file. The path is checked
// before opening (opening some devices has side effects) and the open file once more (the path
// may have been replaced in between); O_NONBLOCK keeps the open itself from blocking and has
// no effect on reads of a regular file.
int open_regular(const std::filesystem::path& path, int flags, const char* what) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) not_regular(path, st.st_mode);
  const int fd = ::open(path.c_str(), flags | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) fail(path, std::string(what) + ": " + std::strerror(errno));
  if (::fstat(fd, &st) == 0 && !S_ISREG(st.st_mode)) {
    ::close(fd);
    not_regular(path, st.st_mode);
  }
  return fd;
}

void sync(int fd, const std::filesystem::path& path) {
  if (::fsync(fd) != 0) fail(path, std::string("fsync failed: ") + std::strerror(errno));
}

std::string fixed_string(const char (&field)[64]) {
  return std::string(field, strnlen(field, 64));
}

std::string version_string(std::uint32_t v) {
  return std::to_string(v >> 16) + "." + std::to_string(v & 0xFFFFu);
}

// Header, names and the valid part of the index of an open GSD 2.x file.
struct Contents {
  Header header;
  std::string namelist;  // the names with their terminators, without the final empty name
  std::vector<std::string> names;
  std::vector<Entry> index;  // complete frames only
  std::uint64_t used_slots;  // index slots before the first location 0 (>= index.size())
  std::uint64_t file_size;
};

// Why index entry `e` cannot be used ("" when it can): `prev_frame` is the frame of the entry
// before it. Its data must lie inside the file: location + N * M * type size <= file size,
// checked without overflow, so that no reader ever allocates for data the file cannot hold.
std::string entry_problem(const Entry& e, const Contents& c, std::uint64_t prev_frame) {
  const std::uint64_t size = type_size(static_cast<Type>(e.type));
  if (size == 0) return "invalid type " + std::to_string(e.type);
  if (e.flags != 0) return "invalid flags";
  if (e.id >= c.names.size()) return "name id " + std::to_string(e.id) + " beyond the namelist";
  if (e.frame < prev_frame || e.frame >= c.header.index_allocated_entries)
    return "frame number " + std::to_string(e.frame) + " out of order";
  const std::uint64_t location = static_cast<std::uint64_t>(e.location);
  const bool inside = e.location > 0 && location <= c.file_size &&
                      (e.N == 0 || e.M == 0 || e.N <= (c.file_size - location) / e.M / size);
  if (!inside) {
    return std::to_string(e.N) + " x " + std::to_string(e.M) + " " +
           std::string(type_name(static_cast<Type>(e.type))) + " values at byte " +
           std::to_string(e.location) + " lie beyond the end of the file (" +
           std::to_string(c.file_size) + " bytes)";
  }
  return "";
}

// Whether some entry after slot k, of a frame after `frame`, is sound and inside the file.
bool later_frame_intact(const Contents& c, std::size_t k, std::size_t used, std::uint64_t frame) {
  for (std::size_t j = k + 1; j < used; ++j) {
    const Entry& e = c.index[j];
    if (e.frame > frame && entry_problem(e, c, frame).empty()) return true;
  }
  return false;
}

// The number of index entries to keep of the `used` slots. By the commit protocol a frame's data
// is on disk before its entries, and the data of later frames lies after it: an unusable entry
// is either the torn or truncated tail of the file (no later frame is intact), whose frame is
// dropped with all later ones, or damage in the middle of the file, an InputError.
std::size_t drop_torn_tail(const Contents& c, std::size_t used, const std::filesystem::path& path) {
  std::uint64_t prev_frame = 0;
  for (std::size_t k = 0; k < used; ++k) {
    const Entry& e = c.index[k];
    const std::string problem = entry_problem(e, c, prev_frame);
    if (problem.empty()) {
      prev_frame = e.frame;
      continue;
    }
    const bool sane_frame = e.frame >= prev_frame && e.frame < c.header.index_allocated_entries;
    const std::uint64_t frame = sane_frame ? e.frame : prev_frame;
    if (later_frame_intact(c, k, used, frame)) {
      const std::string chunk = e.id < c.names.size() ? "chunk '" + c.names[e.id] + "'" : "a chunk";
      fail(path, "damaged index: the entry of " + chunk + " in frame " + std::to_string(frame) +
                     " is invalid (" + problem +
                     ") while later frames are intact; the file was changed or damaged after "
                     "it was written");
    }
    std::size_t valid = k;
    while (valid > 0 && c.index[valid - 1].frame >= frame) --valid;
    return valid;
  }
  return used;
}

Contents load(int fd, const std::filesystem::path& path) {
  Contents c{};
  struct stat st {};
  if (::fstat(fd, &st) != 0) fail(path, std::string("cannot stat: ") + std::strerror(errno));
  c.file_size = static_cast<std::uint64_t>(st.st_size);
  Header& h = c.header;
  if (read_at(fd, &h, sizeof h, 0, path) != sizeof h || h.magic != kMagic)
    fail(path, "not a GSD file (no GSD header)");
  if (h.gsd_version >> 16 != 2)
    fail(path, "unsupported GSD file layer version " + version_string(h.gsd_version) +
                   " (only 2.x is supported)");
  if (strnlen(h.application, 64) == 64 || strnlen(h.schema, 64) == 64)
    fail(path, "corrupt header (unterminated application or schema name)");
  // A block lies inside the file; checked without overflow.
  const auto inside = [&](std::uint64_t location, std::uint64_t count, std::uint64_t size) {
    return location >= sizeof(Header) && location <= c.file_size &&
           count <= (c.file_size - location) / size;
  };
  if (!inside(h.namelist_location, h.namelist_allocated_entries, 64))
    fail(path, "corrupt header (namelist block outside the file)");
  if (!inside(h.index_location, h.index_allocated_entries, sizeof(Entry)))
    fail(path, "corrupt header (index block outside the file)");

  std::string block(h.namelist_allocated_entries * 64, '\0');
  if (read_at(fd, block.data(), block.size(), h.namelist_location, path) != block.size())
    fail(path, "namelist is truncated");
  std::size_t pos = 0;
  while (pos < block.size() && block[pos] != '\0') {
    const std::size_t end = block.find('\0', pos);
    if (end == std::string::npos) fail(path, "corrupt namelist (unterminated name)");
    c.names.push_back(block.substr(pos, end - pos));
    pos = end + 1;
  }
  block.resize(pos);
  c.namelist = std::move(block);

  c.index.resize(h.index_allocated_entries);
  const std::size_t index_bytes = c.index.size() * sizeof(Entry);
  if (read_at(fd, c.index.data(), index_bytes, h.index_location, path) != index_bytes)
    fail(path, "index is truncated");
  std::size_t used = 0;
  while (used < c.index.size() && c.index[used].location != 0) ++used;
  c.used_slots = used;
  c.index.resize(drop_torn_tail(c, used, path));
  return c;
}

// The CRC-32 of a chunk's canonical header (gsd_file.hpp, "Frame checksums"), continuing `crc`.
std::uint32_t header_crc(std::uint32_t crc, std::string_view name, Type type, std::uint64_t N,
                         std::uint32_t M) {
  std::string bytes(name);
  bytes.push_back('\0');
  bytes.push_back(static_cast<char>(type));
  bytes.append(reinterpret_cast<const char*>(&N), sizeof N);  // little-endian (static_assert)
  bytes.append(reinterpret_cast<const char*>(&M), sizeof M);
  return static_cast<std::uint32_t>(
      crc32_z(crc, reinterpret_cast<const Bytef*>(bytes.data()), bytes.size()));
}

std::uint32_t data_crc(std::uint32_t crc, const void* data, std::size_t bytes) {
  if (bytes == 0) return crc;  // (zlib's crc32 of a null buffer is its initial value, 0)
  return static_cast<std::uint32_t>(crc32_z(crc, static_cast<const Bytef*>(data), bytes));
}

void copy_name(char (&field)[64], std::string_view value, const char* what) {
  if (value.size() > 63 || value.find('\0') != std::string_view::npos)
    throw std::invalid_argument(std::string("GSD ") + what + " name must have at most 63 bytes");
  std::memset(field, 0, sizeof field);
  std::memcpy(field, value.data(), value.size());
}

}  // namespace

std::size_t type_size(Type type) {
  constexpr std::size_t sizes[] = {0, 1, 2, 4, 8, 1, 2, 4, 8, 4, 8, 1};
  const auto i = static_cast<std::size_t>(type);
  return i < std::size(sizes) ? sizes[i] : 0;
}

std::string_view type_name(Type type) {
  constexpr std::string_view names[] = {"invalid", "uint8",   "uint16",  "uint32",
                                        "uint64",  "int8",    "int16",   "int32",
                                        "int64",   "float32", "float64", "character"};
  const auto i = static_cast<std::size_t>(type);
  return names[i < std::size(names) ? i : 0];
}

// ---------------------------------------------------------------------------------------------
// Writer

struct Writer::State {
  std::filesystem::path path;
  Fd fd;
  Header header{};
  std::string namelist;                                // committed names, each 0-terminated
  std::unordered_map<std::string, std::uint16_t> ids;  // committed and pending names
  std::string new_names;                               // pending names, each 0-terminated
  std::uint64_t entries = 0;                           // committed index entries
  std::uint64_t frames = 0;                            // completed frames
  std::uint64_t end = 0;      // file size after the last commit; pending data goes after it
  std::uint64_t flushed = 0;  // pending data bytes already written after `end`
  std::vector<Entry> pending;
  std::vector<char> buffer;  // pending data bytes not yet written
  // With checksums on: per pending chunk its name, the CRC-32 of its canonical serialisation
  // and that serialisation's length.
  struct ChunkCrc {
    std::string name;
    std::uint32_t crc;
    std::uint64_t length;
  };
  bool checksums = false;
  std::vector<ChunkCrc> crcs;
  // The chunk being written in pieces (begin_chunk): its bytes in all and given so far.
  struct OpenChunk {
    std::string name;
    std::size_t bytes = 0, given = 0;
  };
  std::optional<OpenChunk> open_chunk;

  State(std::filesystem::path p, int descriptor) : path(std::move(p)), fd(descriptor) {}

  void flush() {
    write_at(fd.get(), buffer.data(), buffer.size(), end + flushed, path);
    flushed += buffer.size();
    buffer.clear();
  }
};

Writer::Writer(std::unique_ptr<State> state) : s_(std::move(state)) {}
Writer::Writer(Writer&&) noexcept = default;
Writer& Writer::operator=(Writer&& other) noexcept {
  if (this != &other) {
    close();
    s_ = std::move(other.s_);
  }
  return *this;
}
Writer::~Writer() {
  close();
}

Writer::State& Writer::state(const char* what) const {
  if (!s_) throw std::logic_error(std::string("gsd::Writer::") + what + " on a closed writer");
  return *s_;
}

Writer Writer::create(const std::filesystem::path& path, std::string_view application,
                      std::string_view schema, std::uint32_t schema_version) {
  Header h{};
  copy_name(h.application, application, "application");
  copy_name(h.schema, schema, "schema");
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) fail(path, std::string("cannot create: ") + std::strerror(errno));
  auto s = std::make_unique<State>(path, fd);
  h.magic = kMagic;
  h.gsd_version = kGsdVersion;
  h.schema_version = schema_version;
  h.index_location = sizeof(Header);
  h.index_allocated_entries = kInitialIndex;
  h.namelist_location = h.index_location + kInitialIndex * sizeof(Entry);
  h.namelist_allocated_entries = kInitialNamelist;
  s->header = h;
  s->end = h.namelist_location + kInitialNamelist * 64;
  std::vector<char> image(s->end, '\0');  // header, empty index, empty namelist
  std::memcpy(image.data(), &h, sizeof h);
  write_at(fd, image.data(), image.size(), 0, path);
  sync(fd, path);
  return Writer(std::move(s));
}

Writer Writer::open_append(const std::filesystem::path& path, std::uint64_t keep_frames) {
  const int fd = open_regular(path, O_RDWR, "cannot open for appending");
  auto s = std::make_unique<State>(path, fd);
  Contents c = load(fd, path);
  if (c.names.size() > 0xFFFF) fail(path, "corrupt namelist (more than 65535 names)");
  s->header = c.header;
  s->namelist = std::move(c.namelist);
  for (std::size_t i = 0; i < c.names.size(); ++i)
    s->ids.emplace(c.names[i], static_cast<std::uint16_t>(i));
  s->entries = c.index.size();
  s->frames = c.index.empty() ? 0 : c.index.back().frame + 1;
  if (keep_frames < s->frames) {  // entries are sorted by frame: drop a tail of them
    s->entries = static_cast<std::uint64_t>(
        std::find_if(c.index.begin(), c.index.end(),
                     [&](const Entry& e) { return e.frame >= keep_frames; }) -
        c.index.begin());
    s->frames = keep_frames;
  }
  s->end = c.file_size;
  if (c.used_slots > s->entries) {  // clear the entries of a dropped (torn) frame
    const std::vector<Entry> zeros(c.used_slots - s->entries, Entry{});
    write_at(fd, zeros.data(), zeros.size() * sizeof(Entry),
             c.header.index_location + s->entries * sizeof(Entry), path);
    sync(fd, path);
  }
  return Writer(std::move(s));
}

void Writer::write_chunk(std::string_view name, Type type, std::uint64_t N, std::uint32_t M,
                         const void* data) {
  if (data == nullptr && N != 0 && M != 0 && type_size(type) != 0)
    throw std::invalid_argument("GSD chunk '" + std::string(name) + "': null data");
  begin_chunk(name, type, N, M);
  append_to_chunk(data, s_->open_chunk->bytes);
  end_chunk();
}

void Writer::begin_chunk(std::string_view name, Type type, std::uint64_t N, std::uint32_t M) {
  State& s = state("begin_chunk");
  const std::size_t size = type_size(type);
  const std::string chunk(name);
  const auto refuse = [&](const std::string& why) {
    throw std::invalid_argument("GSD chunk '" + chunk + "': " + why);
  };
  if (s.open_chunk) refuse("begun while chunk '" + s.open_chunk->name + "' is being written");
  if (size == 0) refuse("invalid type");
  if (type == Type::character) refuse("type character is not readable by GSD 2.0 readers");
  if (chunk.empty() || chunk.find('\0') != std::string::npos) refuse("invalid name");
  if (M != 0 && N > (std::uint64_t{1} << 62) / M / size) refuse("too large");
  const std::size_t bytes = N * M * size;

  auto it = s.ids.find(chunk);
  if (it == s.ids.end()) {
    if (s.ids.size() >= 0xFFFF) refuse("a GSD file holds at most 65535 chunk names");
    it = s.ids.emplace(chunk, static_cast<std::uint16_t>(s.ids.size())).first;
    s.new_names += chunk;
    s.new_names += '\0';
  }
  const std::uint16_t id = it->second;
  if (std::any_of(s.pending.begin(), s.pending.end(), [&](const Entry& e) { return e.id == id; }))
    refuse("written twice in one frame");

  const std::uint64_t location = s.end + s.flushed + s.buffer.size();
  s.pending.push_back(Entry{s.frames, N, static_cast<std::int64_t>(location), M, id,
                            static_cast<std::uint8_t>(type), 0});
  if (s.checksums)
    s.crcs.push_back(
        {chunk, header_crc(0, chunk, type, N, M), chunk.size() + 1 + 1 + 8 + 4 + bytes});
  s.open_chunk = State::OpenChunk{chunk, bytes, 0};
}

void Writer::append_to_chunk(const void* data, std::size_t bytes) {
  State& s = state("append_to_chunk");
  if (!s.open_chunk) throw std::logic_error("GSD: append_to_chunk without begin_chunk");
  State::OpenChunk& c = *s.open_chunk;
  if (bytes > c.bytes - c.given) {
    throw std::logic_error("GSD chunk '" + c.name + "': more data than its N x M values");
  }
  if (bytes == 0) return;
  if (s.checksums) s.crcs.back().crc = data_crc(s.crcs.back().crc, data, bytes);
  c.given += bytes;
  if (s.buffer.size() + bytes > kBufferBytes) s.flush();
  // Never more than kBufferBytes held (a vector left to grow by doubling kept 6 MB per writer).
  if (bytes < kBufferBytes && s.buffer.size() + bytes > s.buffer.capacity())
    s.buffer.reserve(
        std::min(kBufferBytes, std::max(2 * s.buffer.capacity(), s.buffer.size() + bytes)));
  if (bytes >= kBufferBytes) {
    write_at(s.fd.get(), data, bytes, s.end + s.flushed, s.path);
    s.flushed += bytes;
  } else {
    const char* p = static_cast<const char*>(data);
    s.buffer.insert(s.buffer.end(), p, p + bytes);
  }
}

void Writer::end_chunk() {
  State& s = state("end_chunk");
  if (!s.open_chunk) throw std::logic_error("GSD: end_chunk without begin_chunk");
  if (s.open_chunk->given != s.open_chunk->bytes) {
    throw std::logic_error("GSD chunk '" + s.open_chunk->name + "': ended after " +
                           std::to_string(s.open_chunk->given) + " of its " +
                           std::to_string(s.open_chunk->bytes) + " bytes");
  }
  s.open_chunk.reset();
}

void Writer::end_frame() {
  State& s = state("end_frame");
  if (s.open_chunk)
    throw std::logic_error("GSD: end_frame while chunk '" + s.open_chunk->name + "' is open");
  try {
    s.flush();
    Header& h = s.header;
    const int fd = s.fd.get();
    std::uint64_t eof = s.end + s.flushed;
    std::sort(s.pending.begin(), s.pending.end(),
              [](const Entry& a, const Entry& b) { return a.id < b.id; });

    // New names: into the namelist's free space (keeping a final empty name), else a copy at
    // least twice as large at the end of the file.
    bool new_header = false;
    if (!s.new_names.empty()) {
      const std::uint64_t needed = s.namelist.size() + s.new_names.size() + 1;
      std::uint64_t capacity = h.namelist_allocated_entries * 64;
      if (needed <= capacity) {
        const std::string names = s.new_names + '\0';
        write_at(fd, names.data(), names.size(), h.namelist_location + s.namelist.size(), s.path);
      } else {
        capacity = std::max(2 * capacity, (needed + 63) / 64 * 64);
        std::string block = s.namelist + s.new_names;
        block.resize(capacity, '\0');
        write_at(fd, block.data(), block.size(), eof, s.path);
        h.namelist_location = eof;
        h.namelist_allocated_entries = capacity / 64;
        eof += capacity;
        new_header = true;
      }
    }

    // Index: into its free slots, else a doubled copy holding this frame's entries too. GSD
    // readers also require every frame number to be below the index capacity.
    const std::uint64_t n = s.pending.size();
    const std::uint64_t needed = s.entries + n;
    std::uint64_t capacity = h.index_allocated_entries;
    const bool relocate = needed > capacity || (n > 0 && s.frames >= capacity);
    if (relocate) {
      capacity = std::max<std::uint64_t>(capacity, 1);
      while (capacity < needed || capacity <= s.frames) capacity *= 2;
      std::vector<Entry> index(capacity, Entry{});
      const std::size_t old_bytes = s.entries * sizeof(Entry);
      if (read_at(fd, index.data(), old_bytes, h.index_location, s.path) != old_bytes)
        fail(s.path, "index is truncated");
      std::copy(s.pending.begin(), s.pending.end(), index.begin() + s.entries);
      write_at(fd, index.data(), index.size() * sizeof(Entry), eof, s.path);
      h.index_location = eof;
      h.index_allocated_entries = capacity;
      eof += capacity * sizeof(Entry);
      new_header = true;
    }

    // Everything the frame refers to is durable before the frame becomes visible.
    sync(fd, s.path);
    if (new_header) {
      write_at(fd, &h, sizeof h, 0, s.path);
      if (!relocate) sync(fd, s.path);  // the new namelist, before entries that use its ids
    }
    if (!relocate && n > 0)
      write_at(fd, s.pending.data(), n * sizeof(Entry),
               h.index_location + s.entries * sizeof(Entry), s.path);
    if (new_header || n > 0) sync(fd, s.path);

    s.namelist += s.new_names;
    s.new_names.clear();
    s.entries += n;
    s.pending.clear();
    s.crcs.clear();
    s.frames += 1;
    s.end = eof;
    s.flushed = 0;
  } catch (...) {
    s_.reset();  // the in-memory state no longer matches the file
    throw;
  }
}

std::uint64_t Writer::frame_count() const {
  return state("frame_count").frames;
}

void Writer::enable_checksums() {
  state("enable_checksums").checksums = true;
}

std::uint32_t Writer::frame_checksum() const {
  const State& s = state("frame_checksum");
  if (!s.checksums) throw std::logic_error("gsd::Writer::frame_checksum without enable_checksums");
  std::vector<const State::ChunkCrc*> order;
  for (const auto& c : s.crcs) order.push_back(&c);
  std::sort(order.begin(), order.end(), [](auto* a, auto* b) { return a->name < b->name; });
  // The CRC of the concatenation, from the CRCs of its pieces (the data is gone by now).
  std::uint32_t crc = 0;
  for (const auto* c : order) {
    crc = static_cast<std::uint32_t>(crc32_combine(crc, c->crc, static_cast<z_off_t>(c->length)));
  }
  return crc;
}

void Writer::close() noexcept {
  if (!s_) return;
  // Discard an unfinished frame; the file then ends where the last commit left it.
  if (s_->flushed > 0 && ::ftruncate(s_->fd.get(), static_cast<off_t>(s_->end)) != 0) {
    // best effort: bytes past the last commit are never referenced
  }
  s_.reset();
}

// ---------------------------------------------------------------------------------------------
// Reader

struct Reader::State {
  std::filesystem::path path;
  Fd fd;
  Contents contents;
  std::unordered_map<std::string, std::uint16_t> ids;

  State(std::filesystem::path p, int descriptor) : path(std::move(p)), fd(descriptor) {}

  const Entry* find(std::uint64_t frame, std::string_view name) const {
    const auto id = ids.find(std::string(name));
    if (id == ids.end()) return nullptr;
    const auto& index = contents.index;
    auto it = std::lower_bound(index.begin(), index.end(), frame,
                               [](const Entry& e, std::uint64_t f) { return e.frame < f; });
    for (; it != index.end() && it->frame == frame; ++it)
      if (it->id == id->second) return &*it;
    return nullptr;
  }
};

Reader::Reader(const std::filesystem::path& path) {
  const int fd = open_regular(path, O_RDONLY, "cannot open");
  s_ = std::make_unique<State>(path, fd);
  s_->contents = load(fd, path);
  const auto& names = s_->contents.names;
  for (std::size_t i = 0; i < names.size() && i < 0xFFFF; ++i)
    s_->ids.emplace(names[i], static_cast<std::uint16_t>(i));
}

Reader::Reader(Reader&&) noexcept = default;
Reader& Reader::operator=(Reader&&) noexcept = default;
Reader::~Reader() = default;

std::uint64_t Reader::frame_count() const {
  const auto& index = s_->contents.index;
  return index.empty() ? 0 : index.back().frame + 1;
}
std::string Reader::application() const {
  return fixed_string(s_->contents.header.application);
}
std::string Reader::schema() const {
  return fixed_string(s_->contents.header.schema);
}
std::uint32_t Reader::schema_version() const {
  return s_->contents.header.schema_version;
}
std::vector<std::string> Reader::chunk_names() const {
  return s_->contents.names;
}

std::uint32_t Reader::frame_checksum(std::uint64_t frame, std::string_view except) const {
  const auto& names = s_->contents.names;
  std::vector<const Entry*> chunks;
  for (const Entry& e : s_->contents.index)
    if (e.frame == frame && names[e.id] != except) chunks.push_back(&e);
  std::sort(chunks.begin(), chunks.end(),
            [&](const Entry* a, const Entry* b) { return names[a->id] < names[b->id]; });
  std::vector<char> buffer;
  std::uint32_t crc = 0;
  for (const Entry* e : chunks) {
    const auto type = static_cast<Type>(e->type);
    crc = header_crc(crc, names[e->id], type, e->N, e->M);
    // Bounded by the file's size (load): read in pieces of at most kBufferBytes.
    std::uint64_t left = e->N * e->M * type_size(type);
    auto at = static_cast<std::uint64_t>(e->location);
    while (left > 0) {
      const std::size_t piece =
          static_cast<std::size_t>(std::min<std::uint64_t>(left, kBufferBytes));
      buffer.resize(piece);
      read_bytes(at, buffer.data(), piece);
      crc = data_crc(crc, buffer.data(), piece);
      at += piece;
      left -= piece;
    }
  }
  return crc;
}

std::optional<Reader::ChunkInfo> Reader::find(std::uint64_t frame, std::string_view name) const {
  const Entry* e = s_->find(frame, name);
  if (e == nullptr) return std::nullopt;
  return ChunkInfo{static_cast<Type>(e->type), e->N, e->M};
}

Reader::Located Reader::locate(std::uint64_t frame, std::string_view name, Type type) const {
  const std::string where = "chunk '" + std::string(name) + "' in frame " + std::to_string(frame);
  const Entry* e = s_->find(frame, name);
  if (e == nullptr) fail(s_->path, "no " + where);
  const auto stored = static_cast<Type>(e->type);
  if (stored != type)
    fail(s_->path, where + " holds " + std::string(type_name(stored)) + ", not " +
                       std::string(type_name(type)));
  return Located{static_cast<std::uint64_t>(e->location), e->N * e->M};
}

void Reader::read_bytes(std::uint64_t location, void* dst, std::size_t bytes) const {
  if (read_at(s_->fd.get(), dst, bytes, location, s_->path) != bytes)
    fail(s_->path, "chunk data is truncated (file changed while open?)");
}

}  // namespace kairos::gsd

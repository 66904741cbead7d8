#include "core/memory_budget.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

#include "core/error.hpp"

namespace kairos {
namespace {

namespace fs = std::filesystem;

constexpr const char* kLimitVariable = "KAIROS_MEMORY_LIMIT_BYTES";

// Peak resident memory per particle, measured with /usr/bin/time -f %M on Release builds
// (2026-12-02, N = 0.2 to 3.2 million, 0.2 collisions per particle, default outputs; the peak
// includes writing restart.gsd):
//   3D: hard spheres (fcc or random) 320-390 B (165 B since 2026-12-04: outputs written from
//       the engine's arrays in blocks, docs/performance.md), soft spheres (event integrator) 400 B,
//       DEM 510-545 B (also at packing fraction 0.4);
//   2D: hard disks 270-290 B, soft disks (event) 335 B, DEM 405 B;
//   a state read from a file (restart, initial state, trajectory frame): as generated (3D hard
//   spheres: 320 B).
// The figures below cover the DEM, the largest, with ~7 % to spare; for hard spheres they are
// 1.5 to 1.8 times the need. Not covered: stepped potentials with long cut-offs, whose capture
// map lists every pair within a cut-off (stepped Lennard-Jones at rho* = 0.8, r_c = 2.5: 1.5 kB
// per particle).
// Since 2026-12-04 (outputs written from the engine's arrays in blocks, docs/performance.md),
// N = 10^6, the event integrator: 3D hard spheres fcc 164 B, random 259 B, soft spheres 211 B;
// 2D hard disks hex 137 B, random 150 B, soft disks 172 B; the DEM 3D 459 B. The event figures
// below cover these with ~15 % to spare.
constexpr std::uint64_t kBytesPerParticle3D = 580;  // the DEM
constexpr std::uint64_t kBytesPerParticle2D = 440;
constexpr std::uint64_t kEventBytesPerParticle3D = 300;
constexpr std::uint64_t kEventBytesPerParticle2D = 200;
constexpr std::uint64_t kBaseBytes = std::uint64_t{32} << 20;  // program, libraries, buffers

// A cgroup limit this large means "no limit" (v1 writes 2^63 - 4096 for none).
constexpr std::uint64_t kUnlimited = std::uint64_t{1} << 62;

std::optional<std::string> read_text(const fs::path& path) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::optional<std::uint64_t> parse_u64(std::string_view text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.remove_suffix(1);
  std::uint64_t value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc{} || end != text.data() + text.size() || text.empty()) return std::nullopt;
  return value;
}

std::optional<std::uint64_t> read_u64(const fs::path& path) {
  const auto text = read_text(path);
  return text ? parse_u64(*text) : std::nullopt;
}

// The number after `key` on the line starting with it ("MemAvailable:  123 kB", "inactive_file 4").
std::optional<std::uint64_t> field(const std::string& text, std::string_view key) {
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.compare(0, key.size(), key) != 0 || line.size() == key.size()) continue;
    if (line[key.size()] != ' ' && line[key.size()] != ':') continue;
    std::istringstream rest(line.substr(key.size() + 1));
    std::uint64_t value = 0;
    if (rest >> value) return value;
  }
  return std::nullopt;
}

std::optional<std::uint64_t> meminfo_available(const fs::path& meminfo) {
  const auto text = read_text(meminfo);
  if (!text) return std::nullopt;
  const auto kb = field(*text, "MemAvailable:");
  return kb ? std::optional<std::uint64_t>(*kb * 1024) : std::nullopt;
}

// The cgroup path of the memory controller in /proc/self/cgroup: the v2 line "0::<path>", or the
// v1 line "<id>:<controllers with memory>:<path>".
std::optional<fs::path> cgroup_path(const std::string& self_cgroup, bool v2) {
  std::istringstream lines(self_cgroup);
  for (std::string line; std::getline(lines, line);) {
    const auto first = line.find(':');
    const auto second = first == std::string::npos ? first : line.find(':', first + 1);
    if (second == std::string::npos) continue;
    std::string controllers = ",";  // (not "," + ...: a GCC 12 -Wrestrict false positive)
    controllers += line.substr(first + 1, second - first - 1);
    controllers += ',';
    if (v2 ? controllers == ",," : controllers.find(",memory,") != std::string::npos)
      return fs::path(line.substr(second + 1)).relative_path();
  }
  return std::nullopt;
}

// The room left under the limits of the cgroup at `root`/`path` and of all its ancestors up to
// `root`: limit - (usage - inactive file cache), the smallest over the levels that set a limit.
struct CgroupFiles {
  const char* limit;
  const char* usage;
  const char* inactive;  // key in memory.stat
};

std::optional<std::uint64_t> cgroup_room(const fs::path& root, const fs::path& path,
                                         const CgroupFiles& files) {
  std::vector<fs::path> levels{root};
  for (const fs::path& part : path)
    if (!part.empty()) levels.push_back(levels.back() / part);
  std::optional<std::uint64_t> room;
  for (const fs::path& dir : levels) {
    const auto limit = read_u64(dir / files.limit);  // nullopt also for v2's "max"
    if (limit && *limit < kUnlimited) {
      const std::uint64_t usage = read_u64(dir / files.usage).value_or(0);
      const auto stat = read_text(dir / "memory.stat");
      const std::uint64_t cache = stat ? field(*stat, files.inactive).value_or(0) : 0;
      const std::uint64_t used = usage - std::min(usage, cache);
      const std::uint64_t left = *limit - std::min(*limit, used);
      room = room ? std::min(*room, left) : left;
    }
  }
  return room;
}

std::optional<std::uint64_t> environment_limit() {
  const char* text = std::getenv(kLimitVariable);
  if (text == nullptr || *text == '\0') return std::nullopt;
  const auto value = parse_u64(text);
  if (!value) {
    throw InputError(
        fmt::format("{} = '{}' is not a number of bytes: give a whole number (e.g. "
                    "8000000000), or unset it to use the memory detected",
                    kLimitVariable, text));
  }
  return value;
}

}  // namespace

std::optional<AvailableMemory> available_memory(const MemorySources& sources) {
  if (const auto limit = environment_limit()) return AvailableMemory{*limit, kLimitVariable};
  std::optional<AvailableMemory> best;
  const auto consider = [&](std::optional<std::uint64_t> bytes, std::string source) {
    if (bytes && (!best || *bytes < best->bytes)) best = AvailableMemory{*bytes, std::move(source)};
  };
  consider(meminfo_available(sources.meminfo), "MemAvailable in " + sources.meminfo.string());
  if (const auto self = read_text(sources.self_cgroup)) {
    if (const auto path = cgroup_path(*self, true)) {
      consider(cgroup_room(sources.cgroup2_root, *path,
                           {"memory.max", "memory.current", "inactive_file"}),
               "the memory.max of cgroup /" + path->string());
    }
    if (const auto path = cgroup_path(*self, false)) {
      consider(
          cgroup_room(sources.cgroup1_memory_root, *path,
                      {"memory.limit_in_bytes", "memory.usage_in_bytes", "total_inactive_file"}),
          "the memory.limit_in_bytes of cgroup /" + path->string());
    }
  }
  return best;
}

std::uint64_t estimated_run_bytes(std::uint64_t particles, int dimension, RunKind kind) {
  const bool event = kind == RunKind::kEventDriven;
  const std::uint64_t per = dimension == 2
                                ? (event ? kEventBytesPerParticle2D : kBytesPerParticle2D)
                                : (event ? kEventBytesPerParticle3D : kBytesPerParticle3D);
  return kBaseBytes + particles * per;  // no overflow: particles < 2^32
}

std::string format_bytes(std::uint64_t bytes) {
  const double b = static_cast<double>(bytes);
  if (b >= 1024.0 * 1024.0 * 1024.0) return fmt::format("{:.3g} GiB", b / (1024.0 * 1024 * 1024));
  if (b >= 1024.0 * 1024.0) return fmt::format("{:.3g} MiB", b / (1024.0 * 1024.0));
  return fmt::format("{:.3g} kiB", b / 1024.0);
}

void require_memory(std::uint64_t bytes, std::string_view what, const MemorySources& sources) {
  const auto available = available_memory(sources);
  if (!available || bytes <= available->bytes) return;
  throw InputError(fmt::format(
      "{} needs about {}, this machine has {} available ({}): use fewer particles or a machine "
      "with more memory (the estimate is in docs/config.md; {} overrides the memory detected)",
      what, format_bytes(bytes), format_bytes(available->bytes), available->source,
      kLimitVariable));
}

}  // namespace kairos

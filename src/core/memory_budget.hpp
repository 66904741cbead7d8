// Memory estimates checked up front: a run that cannot fit is refused at once with the estimate
// and the memory available, instead of filling memory for minutes and dying of std::bad_alloc
// (or being killed by the kernel without a word).
//
// The memory available to the process is the smallest of
//   - MemAvailable in /proc/meminfo (what the kernel can hand out without swapping), and
//   - for each memory cgroup the process is in (v2: memory.max in /sys/fs/cgroup/<path> and its
//     ancestors; v1: memory.limit_in_bytes under /sys/fs/cgroup/memory), the limit minus the
//     cgroup's usage, less its inactive file cache, which the kernel reclaims first;
// unless the environment variable KAIROS_MEMORY_LIMIT_BYTES (a whole number of bytes) is set:
// then that number, as it is (to test the refusal, or to overrule a wrong estimate).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace kairos {

struct AvailableMemory {
  std::uint64_t bytes = 0;
  std::string source;  // where the figure comes from, for messages
};

// Where available_memory() looks (tests point it at fake trees).
struct MemorySources {
  std::filesystem::path meminfo = "/proc/meminfo";
  std::filesystem::path self_cgroup = "/proc/self/cgroup";
  std::filesystem::path cgroup2_root = "/sys/fs/cgroup";
  std::filesystem::path cgroup1_memory_root = "/sys/fs/cgroup/memory";
};

// The memory this process may still allocate (see above); nullopt when nothing can be read (then
// no check is made). InputError when KAIROS_MEMORY_LIMIT_BYTES is set but not a whole number.
std::optional<AvailableMemory> available_memory(const MemorySources& sources = {});

// The peak resident memory of a run of `particles` particles in `dimension` D, from generating
// (or reading) its state to writing its restart file, whichever integrator runs it (the figures
// and what they leave out are in memory_budget.cpp).
// Which integrator runs the state: the DEM keeps its own, larger layout. kDem, the larger
// estimate, where the integrator is not known.
enum class RunKind { kEventDriven, kDem };
std::uint64_t estimated_run_bytes(std::uint64_t particles, int dimension,
                                  RunKind kind = RunKind::kDem);

// InputError "<what> needs about X GiB, this machine has Y GiB available (...)" when `bytes`
// exceed the memory available; nothing when they fit or nothing is known.
void require_memory(std::uint64_t bytes, std::string_view what, const MemorySources& sources = {});

// "1.5 GiB", "340 MiB", ...: three significant digits.
std::string format_bytes(std::uint64_t bytes);

}  // namespace kairos

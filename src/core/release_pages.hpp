// Gives the memory of an array's front back to the operating system while the array is still
// being read from its back: for a large state converted from one form into another front to
// back (a generated start into the engine's form, that into the engine's records), so that the
// two forms are never both in memory whole (docs/performance.md, "Memory of the whole
// process"). Only whole pages inside the front are released; they read as zero afterwards, so
// the caller must not read the front again (it frees the array once the conversion is done).
#pragma once

#include <cstddef>
#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace kairos {

// Releases the whole pages of elements [from, to) of the array at `data` (elements of type T).
template <class T>
void release_pages(const T* data, std::size_t from, std::size_t to) {
#if defined(__linux__) && defined(MADV_DONTNEED)
  static const auto page = static_cast<std::uintptr_t>(sysconf(_SC_PAGESIZE));
  const auto base = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t first = (base + from * sizeof(T) + page - 1) / page * page;
  const std::uintptr_t last = (base + to * sizeof(T)) / page * page;
  if (last > first) madvise(reinterpret_cast<void*>(first), last - first, MADV_DONTNEED);
#else
  (void)data;
  (void)from;
  (void)to;
#endif
}

// In a front-to-back read, every kStride elements, the pages of the elements read since the
// call before (and of the stride before that: the page it left straddling is whole now).
template <class T>
void release_read_front(const T* data, std::size_t read) {
  constexpr std::size_t kStride = std::size_t{1} << 14;
  if (read == 0 || read % kStride != 0) return;
  release_pages(data, read >= 2 * kStride ? read - 2 * kStride : 0, read);
}

}  // namespace kairos

// An allocator for the engine's large per-particle arrays that asks the kernel for 2 MiB pages.
//
// Event-driven dynamics reads records at random places: at 10^6 particles the working set is
// ~100 MB, and with 4 KiB pages nearly every access also misses the TLB (a page walk per
// record). Linux backs a 2 MiB-aligned region with huge pages when it is marked
// MADV_HUGEPAGE (transparent huge pages in "madvise" mode, the Debian default), so these arrays
// are allocated 2 MiB-aligned and marked. Small arrays (< 2 MiB) use the ordinary allocator.
// Where huge pages are unavailable the advice is ignored and nothing else changes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace kairos {

template <class T>
struct HugePageAllocator {
  using value_type = T;
  static constexpr std::size_t kHugePage = std::size_t{1} << 21;

  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_array_new_length();
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kHugePage) {
      return static_cast<T*>(::operator new (bytes, std::align_val_t{alignof(T)}));
    }
    const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
#if defined(__linux__)
    // A mapping of its own, never memory the heap reuses: pages another array already touched
    // stay 4 KiB pages whatever the advice (after the start state was released, a tenth of
    // the working set at N = 10^6 came back on small pages and the run was 15 % slower).
    void* map = mmap(nullptr, rounded + kHugePage, PROT_READ | PROT_WRITE,
                     MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (map == MAP_FAILED) throw std::bad_alloc();
    const auto start = reinterpret_cast<std::uintptr_t>(map);
    const std::uintptr_t aligned = (start + kHugePage - 1) / kHugePage * kHugePage;
    if (aligned > start) munmap(map, aligned - start);
    const std::size_t tail = start + rounded + kHugePage - (aligned + rounded);
    if (tail > 0) munmap(reinterpret_cast<void*>(aligned + rounded), tail);
    void* p = reinterpret_cast<void*>(aligned);
#if defined(MADV_HUGEPAGE) && !defined(KAIROS_NO_HUGE_PAGES)
    madvise(p, rounded, MADV_HUGEPAGE);  // advice only: failure changes nothing
#endif
#else
    void* p = std::aligned_alloc(kHugePage, rounded);
    if (p == nullptr) throw std::bad_alloc();
#endif
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) noexcept {
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kHugePage) {
      ::operator delete (p, std::align_val_t{alignof(T)});
      return;
    }
#if defined(__linux__)
    munmap(p, (bytes + kHugePage - 1) / kHugePage * kHugePage);
#else
    std::free(p);
#endif
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
};

// A std::vector whose large buffers live on huge pages.
template <class T>
using HugeVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace kairos

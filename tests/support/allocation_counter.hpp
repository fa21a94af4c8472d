// Counts heap allocations: replaces the global operator new and delete (every non-aligned
// form, so that allocation and release always pair malloc with free, also under
// AddressSanitizer, which reports any mismatch; the aligned forms stay the library's, which
// pair among themselves). Include it in exactly one file of a test binary of its own: no other
// test sees the replacement. Set gCounting around the code under test and read gAllocations
// and gLargestAllocation (the largest size asked for while counting).
#pragma once

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <new>

inline std::atomic<bool> gCounting{false};
inline std::atomic<std::uint64_t> gAllocations{0};
inline std::atomic<std::size_t> gLargestAllocation{0};

inline void countAllocation(std::size_t size) {
  if (!gCounting.load(std::memory_order_relaxed)) return;
  gAllocations.fetch_add(1);
  std::size_t seen = gLargestAllocation.load();
  while (size > seen && !gLargestAllocation.compare_exchange_weak(seen, size)) {
  }
}

void* operator new(std::size_t size) {
  countAllocation(size);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  return ::operator new(size);
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  countAllocation(size);
  return std::malloc(size == 0 ? 1 : size);
}
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept {
  return ::operator new(size, tag);
}
// g++ cannot see that the replaced operator new above mallocs, hence the pragma.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
#pragma GCC diagnostic pop

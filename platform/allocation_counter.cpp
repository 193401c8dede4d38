#include "platform/allocation_counter.h"

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <new>

namespace {
// Relaxed: the counts are statistics, read after the code under test has joined or synchronised.
std::atomic<uint64_t> g_allocations{0};
std::atomic<uint64_t> g_deallocations{0};
std::atomic<uint64_t> g_bytes{0};
std::atomic<uint64_t> g_excluded_allocations{0};
// Plain bool (constant-initialised): no TLS wrapper function, and set before the thread allocates.
thread_local bool t_excluded = false;

void* countedAlloc(std::size_t size, std::size_t alignment) {
  (t_excluded ? g_excluded_allocations : g_allocations).fetch_add(1, std::memory_order_relaxed);
  g_bytes.fetch_add(size, std::memory_order_relaxed);
  if (size == 0) size = 1;
  void* p = nullptr;
  if (alignment <= alignof(std::max_align_t)) {
    p = std::malloc(size);
  } else {
    // aligned_alloc wants size to be a multiple of the alignment.
    const std::size_t rounded = (size + alignment - 1) / alignment * alignment;
    p = std::aligned_alloc(alignment, rounded);
  }
  return p;
}

void countedFree(void* p) {
  if (p == nullptr) return;
  g_deallocations.fetch_add(1, std::memory_order_relaxed);
  std::free(p);
}
}  // namespace

namespace plumb {
uint64_t allocationCount() { return g_allocations.load(std::memory_order_relaxed); }
uint64_t deallocationCount() { return g_deallocations.load(std::memory_order_relaxed); }
uint64_t allocatedBytes() { return g_bytes.load(std::memory_order_relaxed); }
void excludeThisThreadFromAllocationCount() { t_excluded = true; }
uint64_t excludedAllocationCount() { return g_excluded_allocations.load(std::memory_order_relaxed); }
}  // namespace plumb

void* operator new(std::size_t size) {
  void* p = countedAlloc(size, alignof(std::max_align_t));
  if (!p) throw std::bad_alloc();
  return p;
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  return countedAlloc(size, alignof(std::max_align_t));
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  return countedAlloc(size, alignof(std::max_align_t));
}
void* operator new(std::size_t size, std::align_val_t al) {
  void* p = countedAlloc(size, static_cast<std::size_t>(al));
  if (!p) throw std::bad_alloc();
  return p;
}
void* operator new[](std::size_t size, std::align_val_t al) { return operator new(size, al); }
void operator delete(void* p) noexcept { countedFree(p); }
void operator delete[](void* p) noexcept { countedFree(p); }
void operator delete(void* p, std::size_t) noexcept { countedFree(p); }
void operator delete[](void* p, std::size_t) noexcept { countedFree(p); }
void operator delete(void* p, std::align_val_t) noexcept { countedFree(p); }
void operator delete[](void* p, std::align_val_t) noexcept { countedFree(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { countedFree(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { countedFree(p); }

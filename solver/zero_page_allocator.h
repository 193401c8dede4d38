#pragma once
// ZeroPageAllocator: storage for large arrays reserved once at start-up (capacity for the worst
// case) of which a run usually writes only a part. The block comes from calloc, which for large
// sizes maps fresh zero pages from the kernel: they cost no resident memory until written. And
// value-initialisation (`resize(n)`) constructs nothing, so the pages stay untouched.
//
// Contract, why it is safe: an element made by resize() holds all-zero bytes, not its default
// member values, so use it only for types whose slots are fully written before they are read
// except for members whose default is zero (LocalBundleAdjuster::Observation: addObservation()
// sets every member but W and V, which start as zero matrices either way). Elements built with
// arguments (push_back, emplace_back) are constructed normally.
//
// Measured (docs/EMBEDDED.md): the 24,000 reserved BA observations are ~10 MB, of which a
// 250-frame TUM run writes a small part.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <utility>

namespace plumb {

template <class T>
struct ZeroPageAllocator {
  using value_type = T;

  ZeroPageAllocator() = default;
  template <class U>
  ZeroPageAllocator(const ZeroPageAllocator<U>&) {}  // NOLINT: rebinding copies nothing

  T* allocate(std::size_t n) {
    // calloc is aligned for max_align_t; Eigen types may want more (AVX: 32), so over-allocate,
    // align by hand and keep calloc's pointer just before the aligned block.
    constexpr std::size_t kAlign = alignof(T) > alignof(void*) ? alignof(T) : alignof(void*);
    void* raw = std::calloc(1, n * sizeof(T) + kAlign + sizeof(void*));
    if (raw == nullptr) throw std::bad_alloc();
    const std::uintptr_t start = reinterpret_cast<std::uintptr_t>(raw) + sizeof(void*);
    const std::uintptr_t aligned = (start + kAlign - 1) & ~(std::uintptr_t(kAlign) - 1);
    reinterpret_cast<void**>(aligned)[-1] = raw;
    return reinterpret_cast<T*>(aligned);
  }
  void deallocate(T* p, std::size_t) {
    if (p != nullptr) std::free(reinterpret_cast<void**>(p)[-1]);
  }

  // Value-initialisation leaves calloc's zero bytes in place (see the contract above).
  template <class U>
  void construct(U*) {}
  template <class U, class A, class... Args>
  void construct(U* p, A&& a, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<A>(a), std::forward<Args>(args)...);
  }

  template <class U>
  bool operator==(const ZeroPageAllocator<U>&) const { return true; }
  template <class U>
  bool operator!=(const ZeroPageAllocator<U>&) const { return false; }
};

}  // namespace plumb

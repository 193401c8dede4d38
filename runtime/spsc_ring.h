#pragma once
// SpscRing<T>: a bounded lock-free queue for exactly one producer thread and one consumer thread.
// Stages pass slot indices and small messages through these rings.
//
// - Capacity is rounded up to a power of two and allocated once, in the constructor; try_push and
//   try_pop never allocate, never block, and return false when full / empty.
// - Indices are free-running 64-bit counters (masked on access), so all `capacity` cells are usable
//   and "full" is simply write - read == capacity. They cannot wrap in practice (2^64 items).
// - The producer owns write_ and a cached copy of read_; the consumer owns read_ and a cached copy
//   of write_. Each pair sits on its own cache line (alignas(64)) so the two threads do not
//   false-share, and each side only reloads the other's index (an acquire load, a cache miss) when
//   its cached copy says full / empty.
// - Memory ordering: the producer constructs the element, then store-releases write_; the consumer
//   load-acquires write_ before reading the element (and symmetrically for read_ when a cell is
//   handed back). That release/acquire pair is the only synchronisation needed.
#include <atomic>
#include <cassert>
#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>

namespace plumb::runtime {

inline constexpr std::size_t kCacheLineBytes = 64;

inline constexpr std::size_t roundUpToPowerOfTwo(std::size_t n) {
  std::size_t p = 1;
  while (p < n) p <<= 1;
  return p;
}

template <typename T>
class SpscRing {
 public:
  explicit SpscRing(std::size_t min_capacity)
      : capacity_(roundUpToPowerOfTwo(min_capacity < 1 ? 1 : min_capacity)),
        mask_(capacity_ - 1),
        cells_(new Cell[capacity_]) {}

  ~SpscRing() {
    // Destroy whatever was pushed and never popped.
    const std::size_t write = producer_.write.load(std::memory_order_acquire);
    for (std::size_t i = consumer_.read.load(std::memory_order_relaxed); i != write; ++i) {
      cellAt(i)->~T();
    }
  }

  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  // Producer side.
  [[nodiscard]] bool try_push(const T& value) { return emplace(value); }
  [[nodiscard]] bool try_push(T&& value) { return emplace(std::move(value)); }

  // Consumer side: moves the oldest element into out.
  [[nodiscard]] bool try_pop(T& out) {
    const std::size_t read = consumer_.read.load(std::memory_order_relaxed);
    if (read == consumer_.cached_write) {
      consumer_.cached_write = producer_.write.load(std::memory_order_acquire);
      if (read == consumer_.cached_write) return false;  // empty
    }
    T* cell = cellAt(read);
    out = std::move(*cell);
    cell->~T();
    consumer_.read.store(read + 1, std::memory_order_release);  // hand the cell back
    return true;
  }

  // Consumer side: the oldest element without removing it, or nullptr when empty.
  const T* front() {
    const std::size_t read = consumer_.read.load(std::memory_order_relaxed);
    if (read == consumer_.cached_write) {
      consumer_.cached_write = producer_.write.load(std::memory_order_acquire);
      if (read == consumer_.cached_write) return nullptr;
    }
    return cellAt(read);
  }

  // Consumer side: true when there is nothing to pop right now.
  bool empty() const {
    return consumer_.read.load(std::memory_order_relaxed) ==
           producer_.write.load(std::memory_order_acquire);
  }
  // Producer side: true when a push would fail right now.
  bool full() const {
    return producer_.write.load(std::memory_order_relaxed) -
               consumer_.read.load(std::memory_order_acquire) ==
           capacity_;
  }
  // Either side; exact only when the other side is idle.
  std::size_t sizeApprox() const {
    const std::size_t read = consumer_.read.load(std::memory_order_acquire);
    const std::size_t write = producer_.write.load(std::memory_order_acquire);
    return write - read;
  }
  std::size_t capacity() const { return capacity_; }

 private:
  struct alignas(T) Cell {
    unsigned char bytes[sizeof(T)];
  };
  struct alignas(kCacheLineBytes) ProducerSide {
    std::atomic<std::size_t> write{0};
    std::size_t cached_read = 0;
  };
  struct alignas(kCacheLineBytes) ConsumerSide {
    std::atomic<std::size_t> read{0};
    std::size_t cached_write = 0;
  };

  template <typename U>
  bool emplace(U&& value) {
    const std::size_t write = producer_.write.load(std::memory_order_relaxed);
    if (write - producer_.cached_read == capacity_) {
      producer_.cached_read = consumer_.read.load(std::memory_order_acquire);
      if (write - producer_.cached_read == capacity_) return false;  // full
    }
    new (cells_[write & mask_].bytes) T(std::forward<U>(value));
    producer_.write.store(write + 1, std::memory_order_release);  // publish the element
    return true;
  }

  T* cellAt(std::size_t index) {
    return std::launder(reinterpret_cast<T*>(cells_[index & mask_].bytes));
  }

  const std::size_t capacity_;
  const std::size_t mask_;
  std::unique_ptr<Cell[]> cells_;
  ProducerSide producer_;
  ConsumerSide consumer_;  // alignas pads the ring itself to whole cache lines
};

}  // namespace plumb::runtime

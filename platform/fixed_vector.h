#pragma once
// FixedVector<T, N>: a vector whose storage is inline and whose capacity is a compile-time
// constant. push_back never allocates; it returns false when full (the caller decides whether
// that is a drop to count or a bug). Used for every per-frame container on the hot path.
#include <algorithm>
#include <array>
#include <cassert>
#include <cstddef>

namespace plumb {

template <typename T, std::size_t N>
class FixedVector {
 public:
  static constexpr std::size_t kCapacity = N;

  [[nodiscard]] bool push_back(const T& value) {
    if (size_ == N) return false;
    data_[size_++] = value;
    return true;
  }
  // Returns a pointer to the new default-initialised element, or nullptr when full.
  [[nodiscard]] T* emplace_back() {
    if (size_ == N) return nullptr;
    data_[size_] = T{};
    return &data_[size_++];
  }
  // *this = other, copying only other's elements, not all N as the copy assignment does (for
  // containers of large T copied per frame); the entries past size() keep what they held.
  void assignUsed(const FixedVector& other) {
    if (this == &other) return;
    std::copy(other.begin(), other.end(), data_.begin());
    size_ = other.size_;
  }
  void pop_back() { assert(size_ > 0); --size_; }
  void clear() { size_ = 0; }
  void resize(std::size_t n) { assert(n <= N); size_ = n; }

  std::size_t size() const { return size_; }
  static constexpr std::size_t capacity() { return N; }
  bool empty() const { return size_ == 0; }
  bool full() const { return size_ == N; }

  T& operator[](std::size_t i) { assert(i < size_); return data_[i]; }
  const T& operator[](std::size_t i) const { assert(i < size_); return data_[i]; }
  T& back() { assert(size_ > 0); return data_[size_ - 1]; }
  const T& back() const { assert(size_ > 0); return data_[size_ - 1]; }

  T* begin() { return data_.data(); }
  T* end() { return data_.data() + size_; }
  const T* begin() const { return data_.data(); }
  const T* end() const { return data_.data() + size_; }
  T* data() { return data_.data(); }
  const T* data() const { return data_.data(); }

 private:
  std::array<T, N> data_{};
  std::size_t size_ = 0;
};

}  // namespace plumb

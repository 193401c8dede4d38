#pragma once
// Little-endian field packing (the recording format, drivers/recording/, and the map file,
// pipeline/loop/saved_map_codec.h + drivers/mapfile/). ByteWriter appends to a caller-owned
// buffer (reused across frames, so steady-state writing does not reallocate); ByteReader reads a
// bounded span and turns every overrun into a sticky failure instead of reading past the end.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace plumb {

class ByteWriter {
 public:
  explicit ByteWriter(std::vector<uint8_t>& buffer) : buffer_(buffer) {}
  void u8(uint8_t v) { buffer_.push_back(v); }
  void u16(uint16_t v) { littleEndian(v, 2); }
  void u32(uint32_t v) { littleEndian(v, 4); }
  void u64(uint64_t v) { littleEndian(v, 8); }
  void i32(int32_t v) { u32(static_cast<uint32_t>(v)); }
  void i64(int64_t v) { u64(static_cast<uint64_t>(v)); }
  void f64(double v) {
    uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    u64(bits);
  }
  void f32(float v) {
    uint32_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    u32(bits);
  }
  void bytes(const void* data, std::size_t size) {
    const auto* p = static_cast<const uint8_t*>(data);
    buffer_.insert(buffer_.end(), p, p + size);
  }
  // Overwrites 4 bytes at `offset` (for sizes and CRCs known only after the payload).
  void patchU32(std::size_t offset, uint32_t v) {
    for (int i = 0; i < 4; ++i) buffer_[offset + i] = static_cast<uint8_t>(v >> (8 * i));
  }
  std::size_t size() const { return buffer_.size(); }

 private:
  void littleEndian(uint64_t v, int n) {
    for (int i = 0; i < n; ++i) buffer_.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  std::vector<uint8_t>& buffer_;
};

class ByteReader {
 public:
  ByteReader(const uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  uint8_t u8() { return static_cast<uint8_t>(littleEndian(1)); }
  uint16_t u16() { return static_cast<uint16_t>(littleEndian(2)); }
  uint32_t u32() { return static_cast<uint32_t>(littleEndian(4)); }
  uint64_t u64() { return littleEndian(8); }
  int32_t i32() { return static_cast<int32_t>(u32()); }
  int64_t i64() { return static_cast<int64_t>(u64()); }
  double f64() {
    const uint64_t bits = u64();
    double v;
    std::memcpy(&v, &bits, sizeof v);
    return v;
  }
  float f32() {
    const uint32_t bits = u32();
    float v;
    std::memcpy(&v, &bits, sizeof v);
    return v;
  }
  // Returns a pointer to the next `n` bytes and skips them, or nullptr (and fails) on overrun.
  const uint8_t* span(std::size_t n) {
    if (!ok_ || n > size_ - pos_) { ok_ = false; return nullptr; }
    const uint8_t* p = data_ + pos_;
    pos_ += n;
    return p;
  }
  bool ok() const { return ok_; }
  std::size_t position() const { return pos_; }
  std::size_t remaining() const { return ok_ ? size_ - pos_ : 0; }

 private:
  uint64_t littleEndian(int n) {
    const uint8_t* p = span(static_cast<std::size_t>(n));
    if (!p) return 0;
    uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= static_cast<uint64_t>(p[i]) << (8 * i);
    return v;
  }
  const uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  bool ok_ = true;
};

}  // namespace plumb

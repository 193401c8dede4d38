#pragma once
// A large zero-filled buffer backed by transparent huge pages where the OS offers them, for data
// written once near start-up and read for the rest of the run (synthetic scene textures).
//
// Why: first touching fresh memory costs a page fault per 4 KiB page (~2 us each on a loaded
// virtual machine), so writing ~15 MiB of textures paid ~10 ms in faults alone. On Linux the
// buffer is an anonymous mapping aligned to 2 MiB with madvise(MADV_HUGEPAGE): where transparent
// huge pages are enabled ("always" or "madvise"), a fault maps 2 MiB at once. Elsewhere, or when
// the kernel declines, it is ordinary memory with ordinary faults; nothing else changes.
#include <cstddef>
#include <cstdint>

namespace plumb {

class HugePageBuffer {
 public:
  HugePageBuffer() = default;
  // bytes > 0; data() is null if the memory could not be had.
  explicit HugePageBuffer(std::size_t bytes);
  ~HugePageBuffer();
  HugePageBuffer(HugePageBuffer&& other) noexcept;
  HugePageBuffer& operator=(HugePageBuffer&& other) noexcept;
  HugePageBuffer(const HugePageBuffer&) = delete;
  HugePageBuffer& operator=(const HugePageBuffer&) = delete;

  uint8_t* data() const { return data_; }
  std::size_t size() const { return size_; }

 private:
  void release();

  uint8_t* data_ = nullptr;     // 2 MiB aligned inside the mapping
  std::size_t size_ = 0;
  void* mapping_ = nullptr;     // what to unmap (or free)
  std::size_t mapping_bytes_ = 0;
};

}  // namespace plumb

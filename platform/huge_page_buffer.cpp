#include "platform/huge_page_buffer.h"

#include <cstdlib>
#include <utility>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace plumb {
namespace {
constexpr std::size_t kHugePage = std::size_t(2) << 20;
}

HugePageBuffer::HugePageBuffer(std::size_t bytes) {
  if (bytes == 0) return;
#if defined(__linux__)
  // One huge page of slack, so that the buffer can start on a 2 MiB boundary.
  const std::size_t mapping_bytes = bytes + kHugePage;
  void* mapping = mmap(nullptr, mapping_bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (mapping != MAP_FAILED) {
    const std::uintptr_t start = (reinterpret_cast<std::uintptr_t>(mapping) + kHugePage - 1) & ~(kHugePage - 1);
    data_ = reinterpret_cast<uint8_t*>(start);
    size_ = bytes;
    mapping_ = mapping;
    mapping_bytes_ = mapping_bytes;
#if defined(MADV_HUGEPAGE)
    madvise(data_, bytes, MADV_HUGEPAGE);  // advice only: a refusal leaves ordinary pages
#endif
    return;
  }
#endif
  mapping_ = std::calloc(bytes, 1);
  data_ = static_cast<uint8_t*>(mapping_);
  size_ = mapping_ ? bytes : 0;
}

HugePageBuffer::~HugePageBuffer() { release(); }

HugePageBuffer::HugePageBuffer(HugePageBuffer&& other) noexcept { *this = std::move(other); }

HugePageBuffer& HugePageBuffer::operator=(HugePageBuffer&& other) noexcept {
  if (this != &other) {
    release();
    std::swap(data_, other.data_);
    std::swap(size_, other.size_);
    std::swap(mapping_, other.mapping_);
    std::swap(mapping_bytes_, other.mapping_bytes_);
  }
  return *this;
}

void HugePageBuffer::release() {
  if (mapping_) {
#if defined(__linux__)
    if (mapping_bytes_) munmap(mapping_, mapping_bytes_);
    else std::free(mapping_);
#else
    std::free(mapping_);
#endif
  }
  data_ = nullptr;
  size_ = 0;
  mapping_ = nullptr;
  mapping_bytes_ = 0;
}

}  // namespace plumb

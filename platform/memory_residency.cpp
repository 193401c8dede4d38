#include "platform/memory_residency.h"

#include <algorithm>
#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace plumb {
namespace {

#if defined(__linux__) && !defined(MADV_POPULATE_WRITE)
constexpr int MADV_POPULATE_WRITE = 23;  // Linux 5.14 (older headers lack the name)
#endif

std::size_t pageBytes() {
#if defined(__linux__)
  static const std::size_t page = std::size_t(sysconf(_SC_PAGESIZE));
  return page;
#else
  return 4096;
#endif
}

// One byte per page read and written back: the page is mapped writable, the value kept.
void touchPages(char* data, std::size_t bytes) {
  const std::size_t page = pageBytes();
  volatile char* p = data;
  for (std::size_t i = 0; i < bytes; i += page) p[i] = p[i];
  if (bytes > 0) p[bytes - 1] = p[bytes - 1];
}

// The whole pages inside [data, data + bytes): [*first, *last) (empty when last <= first).
void wholePages(void* data, std::size_t bytes, std::uintptr_t* first, std::uintptr_t* last) {
  const std::size_t page = pageBytes();
  const std::uintptr_t begin = reinterpret_cast<std::uintptr_t>(data);
  *first = (begin + page - 1) & ~(std::uintptr_t(page) - 1);
  *last = (begin + bytes) & ~(std::uintptr_t(page) - 1);
}

}  // namespace

bool populateForWrite(void* data, std::size_t bytes) {
  if (data == nullptr || bytes == 0) return true;
#if defined(__linux__)
  std::uintptr_t first = 0, last = 0;
  wholePages(data, bytes, &first, &last);
  if (last <= first) return true;
  void* const start = reinterpret_cast<void*>(first);
  if (madvise(start, last - first, MADV_POPULATE_WRITE) != 0) return false;
  // Some layers accept advice they do not act on (qemu-user returns success for any madvise it
  // does not know): the last whole page must be resident now, or nothing was done.
  unsigned char resident = 0;
  void* const last_page = reinterpret_cast<void*>(last - pageBytes());
  return mincore(last_page, pageBytes(), &resident) == 0 && (resident & 1) != 0;
#else
  return false;
#endif
}

void makeResident(void* data, std::size_t bytes) {
  if (data == nullptr || bytes == 0) return;
  char* const begin = static_cast<char*>(data);
  std::uintptr_t first = 0, last = 0;
  wholePages(data, bytes, &first, &last);
  // The kernel maps the whole pages; the partial pages at either end are touched by hand.
  if (last > first && populateForWrite(data, bytes)) {
    const std::uintptr_t start = reinterpret_cast<std::uintptr_t>(begin);
    touchPages(begin, first - start);
    touchPages(reinterpret_cast<char*>(last), start + bytes - last);
    return;
  }
  touchPages(begin, bytes);
}

void ResidencyQueue::add(void* data, std::size_t bytes) {
  if (data == nullptr || bytes == 0) return;
  ranges_.push_back(Range{static_cast<char*>(data), bytes});
  pending_ += bytes;
  queued_ += bytes;
}

std::size_t ResidencyQueue::step(std::size_t max_bytes) {
  while (max_bytes > 0 && range_ < ranges_.size()) {
    const Range& r = ranges_[range_];
    const std::size_t n = std::min(max_bytes, r.bytes - offset_);
    makeResident(r.data + offset_, n);
    offset_ += n;
    pending_ -= n;
    max_bytes -= n;
    if (offset_ == r.bytes) {
      ++range_;
      offset_ = 0;
    }
  }
  return pending_;
}

}  // namespace plumb

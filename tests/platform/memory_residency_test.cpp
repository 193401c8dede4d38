// makeResident() maps pages without changing a byte; ResidencyQueue steps through its ranges in
// order and reports what is left.
#include "platform/memory_residency.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <vector>

#include <sys/mman.h>
#include <unistd.h>

namespace plumb {
namespace {

class Mapping {
 public:
  explicit Mapping(std::size_t bytes) : bytes_(bytes) {
    data_ = static_cast<uint8_t*>(mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
  }
  ~Mapping() { munmap(data_, bytes_); }
  uint8_t* data() const { return data_; }
  // Pages of [offset, offset + bytes) the kernel reports resident (mincore).
  std::size_t residentPages(std::size_t offset, std::size_t bytes) const {
    const std::size_t page = std::size_t(sysconf(_SC_PAGESIZE));
    std::vector<unsigned char> flags((bytes + page - 1) / page);
    if (mincore(data_ + offset, bytes, flags.data()) != 0) return SIZE_MAX;
    std::size_t n = 0;
    for (unsigned char f : flags) n += f & 1;
    return n;
  }

 private:
  uint8_t* data_;
  std::size_t bytes_;
};

TEST(MemoryResidency, MakeResidentMapsEveryPageAndKeepsTheBytes) {
  const std::size_t page = std::size_t(sysconf(_SC_PAGESIZE));
  Mapping m(64 * page);
  ASSERT_NE(m.data(), MAP_FAILED);
  EXPECT_EQ(m.residentPages(0, 64 * page), 0u);
  m.data()[5 * page + 17] = 42;  // live data in the range
  m.data()[40 * page - 1] = 7;
  // An unaligned range: from inside page 3 to inside page 50.
  makeResident(m.data() + 3 * page + 100, 47 * page);
  EXPECT_EQ(m.residentPages(3 * page, 48 * page), 48u);
  EXPECT_EQ(m.residentPages(51 * page, 13 * page), 0u);  // nothing beyond the range
  EXPECT_EQ(m.data()[5 * page + 17], 42);
  EXPECT_EQ(m.data()[40 * page - 1], 7);
  for (std::size_t i = 3 * page + 100; i < 50 * page + 100; ++i) {
    if (i == 5 * page + 17 || i == 40 * page - 1) continue;
    ASSERT_EQ(m.data()[i], 0) << i;
  }
}

TEST(MemoryResidency, PopulateForWriteMapsWholePagesWithoutTouchingAByte) {
  const std::size_t page = std::size_t(sysconf(_SC_PAGESIZE));
  Mapping m(16 * page);
  ASSERT_NE(m.data(), MAP_FAILED);
  m.data()[2 * page + 5] = 9;
  // From inside page 1 to inside page 9: whole pages 2..8 are populated; the partial pages at the
  // ends are left alone (it never touches a byte by hand).
  if (!populateForWrite(m.data() + page + 10, 8 * page)) {
    GTEST_SKIP() << "the kernel did not populate (no MADV_POPULATE_WRITE before Linux 5.14; "
                    "qemu-user accepts the advice and ignores it)";
  }
  EXPECT_EQ(m.residentPages(2 * page, 7 * page), 7u);
  EXPECT_EQ(m.residentPages(page, page), 0u);
  EXPECT_EQ(m.residentPages(9 * page, 7 * page), 0u);
  EXPECT_EQ(m.data()[2 * page + 5], 9);
}

TEST(MemoryResidency, QueueStepsThroughRangesInOrder) {
  const std::size_t page = std::size_t(sysconf(_SC_PAGESIZE));
  Mapping m(32 * page);
  ASSERT_NE(m.data(), MAP_FAILED);
  ResidencyQueue queue;
  queue.add(m.data(), 4 * page);
  queue.add(nullptr, 100);          // ignored
  queue.add(m.data() + 8 * page, 0);  // ignored
  queue.add(m.data() + 16 * page, 10 * page);
  EXPECT_EQ(queue.queuedBytes(), 14 * page);
  EXPECT_EQ(queue.pendingBytes(), 14 * page);
  EXPECT_EQ(queue.step(3 * page), 11 * page);
  EXPECT_EQ(m.residentPages(0, 4 * page), 3u);
  EXPECT_EQ(queue.step(3 * page), 8 * page);  // the first range's last page, then two more
  EXPECT_EQ(m.residentPages(0, 4 * page), 4u);
  EXPECT_EQ(m.residentPages(16 * page, 10 * page), 2u);
  EXPECT_EQ(queue.step(SIZE_MAX), 0u);
  EXPECT_EQ(m.residentPages(16 * page, 10 * page), 10u);
  EXPECT_EQ(m.residentPages(4 * page, 12 * page), 0u);  // the gap between the ranges
  EXPECT_EQ(queue.step(page), 0u);                       // nothing left: no-op
}

}  // namespace
}  // namespace plumb

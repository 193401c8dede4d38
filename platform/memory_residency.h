#pragma once
// Reserved memory made resident later, a slice at a time, off the first frame's path.
//
// Why: the bounded stores (loop closer, keyframe database, pose-graph factor) are sized for the
// worst case at start-up, and were written with zeros there so that a long run's resident set
// does not grow as they fill (issue 12: RSS at frame 10,000 = frame 1,000). Writing ~8 MiB before
// the first frame cost ~5 ms of first-touch page faults on the first pose (docs/EMBEDDED.md). Now
// the owner queues the reserved ranges at construction (nothing is touched) and calls step() once
// per keyframe after the first: the memory is resident after a few keyframes, and RSS is flat
// from then on, as before.
//
// makeResident() changes no byte: it asks the kernel to map the pages writable
// (madvise(MADV_POPULATE_WRITE), Linux 5.14+) and, where that is refused, reads and writes back
// one byte per page. So a range may hold live data. Not thread-safe: the owner's thread only.
#include <cstddef>
#include <vector>

namespace plumb {

// Pages of [data, data + bytes) resident and writable; contents unchanged.
void makeResident(void* data, std::size_t bytes);
// The same through the kernel only (MADV_POPULATE_WRITE on the whole pages inside the range):
// never reads or writes a byte, so another thread may be using the memory meanwhile. False where
// it was not done: the kernel cannot (before Linux 5.14, other systems), or an emulator accepted
// the advice without acting on it (checked with mincore on the last page).
bool populateForWrite(void* data, std::size_t bytes);

class ResidencyQueue {
 public:
  // Queues a range (construction time; nothing is touched). Empty ranges are ignored.
  void add(void* data, std::size_t bytes);
  // Makes up to max_bytes more of the queued ranges resident, in queue order. Returns the bytes
  // still pending.
  std::size_t step(std::size_t max_bytes);
  std::size_t pendingBytes() const { return pending_; }
  std::size_t queuedBytes() const { return queued_; }

 private:
  struct Range {
    char* data;
    std::size_t bytes;
  };
  std::vector<Range> ranges_;
  std::size_t range_ = 0;   // the first range not wholly resident
  std::size_t offset_ = 0;  // bytes of ranges_[range_] done
  std::size_t pending_ = 0;
  std::size_t queued_ = 0;
};

}  // namespace plumb

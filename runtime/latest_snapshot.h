#pragma once
// LatestSnapshot<T>: the feedback channel from a later stage back to an earlier one (mapping ->
// tracking: "here is the refreshed local map"). One writer thread, one reader thread, three
// preallocated buffers (triple buffering):
//
//   writer fills writeBuffer() --publish(v)--> middle --acquireLatest()--> reader's front buffer
//
// publish() and acquireLatest() are single atomic exchanges: neither side ever waits for the other
// or allocates, and the reader always gets a complete snapshot, never a half-written one. The
// reader sees the newest published version (intermediate ones may be skipped); the version number
// (e.g. the frame index the map was built from) says which one. In lock-step runs the writer
// publishes before the reader's next step, so the reader sees exactly the single-threaded state.
//
// After publish() the writer's new back buffer holds an older snapshot: the writer must overwrite
// all of it (copy assignment into preallocated storage) before the next publish.
#include <array>
#include <atomic>
#include <cstdint>
#include <limits>

namespace plumb::runtime {

template <typename T>
class LatestSnapshot {
 public:
  static constexpr uint64_t kNoVersion = std::numeric_limits<uint64_t>::max();

  LatestSnapshot() { versions_.fill(kNoVersion); }
  LatestSnapshot(const LatestSnapshot&) = delete;
  LatestSnapshot& operator=(const LatestSnapshot&) = delete;

  // Writer side: the buffer to fill for the next publish.
  T& writeBuffer() { return buffers_[back_]; }

  // Writer side: makes writeBuffer() the newest snapshot.
  void publish(uint64_t version) {
    versions_[back_] = version;
    // acq_rel: release our writes into the buffer; acquire the reader's release of the buffer we
    // get back (it may just have finished reading it).
    const uint8_t previous = middle_.exchange(static_cast<uint8_t>(back_ | kFreshBit),
                                              std::memory_order_acq_rel);
    back_ = previous & kIndexMask;
    published_version_.store(version, std::memory_order_release);
  }

  // Reader side: the newest published snapshot (swapped in if a newer one arrived since the last
  // call), or nullptr before the first publish. Valid until the next acquireLatest().
  const T* acquireLatest(uint64_t* version = nullptr) {
    if (middle_.load(std::memory_order_relaxed) & kFreshBit) {
      const uint8_t previous = middle_.exchange(front_, std::memory_order_acq_rel);
      front_ = previous & kIndexMask;
    }
    if (version != nullptr) *version = versions_[front_];
    return versions_[front_] == kNoVersion ? nullptr : &buffers_[front_];
  }

  // Either side: version of the newest publish (kNoVersion before the first).
  uint64_t publishedVersion() const { return published_version_.load(std::memory_order_acquire); }

 private:
  static constexpr uint8_t kIndexMask = 0x3;
  static constexpr uint8_t kFreshBit = 0x4;

  std::array<T, 3> buffers_{};
  std::array<uint64_t, 3> versions_{};  // each entry travels with its buffer's ownership
  uint8_t back_ = 0;                     // writer-owned
  uint8_t front_ = 2;                    // reader-owned
  alignas(64) std::atomic<uint8_t> middle_{1};  // own cache line: both sides hit it
  std::atomic<uint64_t> published_version_{kNoVersion};
};

}  // namespace plumb::runtime

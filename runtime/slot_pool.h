#pragma once
// SlotPool<T>: N objects of T created once at start-up and reused for the whole run; the pipeline
// passes their indices, never the objects.
//
// Ownership of a slot is always with exactly one party, which is what lets stages touch slot
// contents without locks:
//   free ring --tryAcquire--> source --ring--> stage 1 --ring--> ... --> last stage --release--> free ring
// Only the source acquires (it is the free ring's single consumer) and only the last stage releases
// (its single producer), so the free list is itself an SpscRing. A stage owns a slot from the moment
// it pops the index until it pushes it on; the ring's release/acquire hand-off makes everything the
// previous owner wrote visible to the next.
//
// An empty free ring is reported, not waited on: in real-time mode the source drops that frame and
// counts it; in fast mode it waits on releasedBell(), which release() rings.
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "runtime/doorbell.h"
#include "runtime/spsc_ring.h"

namespace plumb::runtime {

using SlotIndex = uint32_t;

template <typename T>
class SlotPool {
 public:
  // Default-constructs slot_count slots. Per-frame buffers inside T (images, feature arrays) should
  // be sized here or on first use, never per frame.
  explicit SlotPool(std::size_t slot_count) : slots_(slot_count), free_(slot_count) {
    for (std::size_t i = 0; i < slot_count; ++i) {
      const bool pushed = free_.try_push(static_cast<SlotIndex>(i));
      assert(pushed);
      (void)pushed;
    }
  }

  SlotPool(const SlotPool&) = delete;
  SlotPool& operator=(const SlotPool&) = delete;

  // Source side only. False when every slot is in flight.
  [[nodiscard]] bool tryAcquire(SlotIndex* index) { return free_.try_pop(*index); }

  // Last stage only: the slot's journey is over.
  void release(SlotIndex index) {
    assert(index < slots_.size());
    // Cannot fail: the ring holds as many cells as there are slots and each index is in it once.
    const bool pushed = free_.try_push(index);
    assert(pushed);
    (void)pushed;
    released_bell_.ring();
  }

  T& operator[](SlotIndex index) { return slots_[index]; }
  const T& operator[](SlotIndex index) const { return slots_[index]; }
  std::size_t size() const { return slots_.size(); }
  // Exact when the pipeline is idle (e.g. after a run: every slot must be back).
  std::size_t freeCount() const { return free_.sizeApprox(); }
  Doorbell& releasedBell() { return released_bell_; }

 private:
  std::vector<T> slots_;  // sized once; never resized, so references stay valid
  SpscRing<SlotIndex> free_;
  Doorbell released_bell_;
};

}  // namespace plumb::runtime

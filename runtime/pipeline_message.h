#pragma once
// What travels through the rings between stages: a slot index and what it means. End of stream and
// errors are messages too, so they arrive in order behind the frames that preceded them.
#include <cstdint>

#include "runtime/slot_pool.h"

namespace plumb::runtime {

struct PipelineMessage {
  enum class Kind : uint8_t {
    kFrame,        // process slot
    kPassThrough,  // slot must reach the last stage unprocessed (an upstream stage failed)
    kError,        // slot's frame failed upstream: stop processing, keep passing slots on
    kEndOfStream,  // nothing follows; carries no slot
  };
  Kind kind = Kind::kEndOfStream;
  SlotIndex slot = 0;  // meaningless for kEndOfStream

  // Every message but end of stream owns a slot, which the last stage returns to the pool.
  bool carriesSlot() const { return kind != Kind::kEndOfStream; }
};

}  // namespace plumb::runtime

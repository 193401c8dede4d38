#pragma once
// FaultInjectingSource: wraps any FrameSource and makes it behave like a misbehaving live sensor,
// following a fixed plan, so supervision (ResilientSource) and the pipeline can be tested against
// exactly known faults. Faults are keyed to the index of the next inner frame to be read.
//
//   kDrop        the next `count` inner frames are read and thrown away (a sequence gap)
//   kStall       `count` calls return kNoFrame before the frame is read (sensor timeout)
//   kError       one call returns kError; reopen() then succeeds at the first attempt
//   kDisconnect  every call returns kError until reopen() has failed `failed_reopens` times and
//                then succeeded; `count` inner frames are lost while the device was away
#include <cstdint>
#include <memory>
#include <vector>

#include "drivers/common/frame_source.h"

namespace plumb {

enum class FaultKind { kDrop, kStall, kError, kDisconnect };

struct FaultEvent {
  uint64_t at_frame = 0;  // index of the inner frame (0-based) before which the fault strikes
  FaultKind kind = FaultKind::kDrop;
  int count = 1;           // frames dropped / calls stalled / frames lost while disconnected
  int failed_reopens = 0;  // kDisconnect: reopen() attempts that fail before one succeeds
};

// What was actually injected (compare with what the supervisor observed).
struct InjectedFaults {
  uint64_t frames_dropped = 0;  // by kDrop and lost while disconnected
  uint64_t stall_calls = 0;
  uint64_t errors = 0;          // kError events + kDisconnect events
  uint64_t disconnects = 0;
  uint64_t failed_reopens = 0;
  uint64_t successful_reopens = 0;
};

class FaultInjectingSource : public FrameSource {
 public:
  // `plan` need not be sorted. Events at the same frame strike in plan order.
  FaultInjectingSource(std::unique_ptr<FrameSource> inner, std::vector<FaultEvent> plan);

  SourceResult next(RgbdImage& out) override;
  const PinholeCamera& camera() const override { return inner_->camera(); }
  std::string describe() const override { return "faulty(" + inner_->describe() + ")"; }
  const Status& lastError() const override { return error_; }
  Status reopen() override;
  bool isLive() const override { return true; }  // it plays the part of a live sensor

  const InjectedFaults& injected() const { return injected_; }

 private:
  enum class State { kStreaming, kFailed };
  SourceResult readInner(RgbdImage& out);

  std::unique_ptr<FrameSource> inner_;
  std::vector<FaultEvent> plan_;  // sorted by at_frame (stable)
  std::size_t next_event_ = 0;
  uint64_t inner_frames_read_ = 0;
  int stall_calls_left_ = 0;
  State state_ = State::kStreaming;
  int reopen_failures_left_ = 0;
  int frames_to_lose_on_reopen_ = 0;
  InjectedFaults injected_;
  Status error_;
};

}  // namespace plumb

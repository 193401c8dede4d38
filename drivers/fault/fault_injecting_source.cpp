#include "drivers/fault/fault_injecting_source.h"

#include <algorithm>

namespace plumb {

FaultInjectingSource::FaultInjectingSource(std::unique_ptr<FrameSource> inner,
                                           std::vector<FaultEvent> plan)
    : inner_(std::move(inner)), plan_(std::move(plan)) {
  std::stable_sort(plan_.begin(), plan_.end(), [](const FaultEvent& a, const FaultEvent& b) {
    return a.at_frame < b.at_frame;
  });
}

SourceResult FaultInjectingSource::readInner(RgbdImage& out) {
  const SourceResult r = inner_->next(out);
  if (r == SourceResult::kFrame) ++inner_frames_read_;
  if (r == SourceResult::kError) error_ = inner_->lastError();
  return r;
}

SourceResult FaultInjectingSource::next(RgbdImage& out) {
  if (state_ == State::kFailed) return SourceResult::kError;
  if (stall_calls_left_ > 0) {
    --stall_calls_left_;
    ++injected_.stall_calls;
    return SourceResult::kNoFrame;
  }
  while (next_event_ < plan_.size() && plan_[next_event_].at_frame <= inner_frames_read_) {
    const FaultEvent& event = plan_[next_event_++];
    switch (event.kind) {
      case FaultKind::kDrop:
        for (int i = 0; i < event.count; ++i) {
          const SourceResult r = readInner(out);
          if (r != SourceResult::kFrame) return r;
          ++injected_.frames_dropped;
        }
        break;
      case FaultKind::kStall:
        if (event.count > 0) {
          stall_calls_left_ = event.count - 1;
          ++injected_.stall_calls;
          return SourceResult::kNoFrame;
        }
        break;
      case FaultKind::kError:
      case FaultKind::kDisconnect: {
        const bool disconnect = event.kind == FaultKind::kDisconnect;
        state_ = State::kFailed;
        reopen_failures_left_ = disconnect ? event.failed_reopens : 0;
        frames_to_lose_on_reopen_ = disconnect ? event.count : 0;
        ++injected_.errors;
        if (disconnect) ++injected_.disconnects;
        error_ = Status::Error(describe() + (disconnect ? ": injected disconnect before frame "
                                                        : ": injected read error before frame ") +
                               std::to_string(event.at_frame));
        return SourceResult::kError;
      }
    }
  }
  return readInner(out);
}

Status FaultInjectingSource::reopen() {
  if (state_ != State::kFailed) return Status::Ok();
  if (reopen_failures_left_ > 0) {
    --reopen_failures_left_;
    ++injected_.failed_reopens;
    return Status::Error(describe() + ": injected reopen failure (device not back yet)");
  }
  ++injected_.successful_reopens;
  state_ = State::kStreaming;
  // Frames the sensor produced while it was away never reach us.
  RgbdImage scratch;
  for (; frames_to_lose_on_reopen_ > 0; --frames_to_lose_on_reopen_) {
    if (readInner(scratch) != SourceResult::kFrame) break;
    ++injected_.frames_dropped;
  }
  error_ = Status::Ok();
  return Status::Ok();
}

}  // namespace plumb

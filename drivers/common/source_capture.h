#pragma once
// SourceCapture: any FrameSource as the runner's capture step (sensor/frame_capture.h). The next
// frame is read ahead with next() into a staging image in prepareNext(); take() swaps it into the
// slot's image (cv::Mat headers only), drop() forgets it. Every source works this way, live or
// replayed: a TUM folder decodes its next PNG pair ahead exactly as a camera's frame arrives ahead.
#include <atomic>
#include <cstdint>

#include "drivers/common/frame_source.h"
#include "sensor/frame_capture.h"

namespace plumb {

class SourceCapture final : public FrameCapture {
 public:
  // `stop` (optional, e.g. set by a SIGINT handler): a live source that has no frame (kNoFrame)
  // ends the capture once it is set, instead of being asked again forever; the source gets it too
  // (FrameSource::setStopFlag), so a reconnection in progress gives up waiting.
  explicit SourceCapture(FrameSource& source, const std::atomic<bool>* stop = nullptr)
      : source_(source), stop_(stop) {
    source_.setStopFlag(stop);
  }
  ~SourceCapture() override { source_.setStopFlag(nullptr); }

  const PinholeCamera& camera() const override { return source_.camera(); }

  bool prepareNext(int64_t* t_recorded_ns) override;
  Status take(RgbdImage& out) override;
  bool drop(uint64_t* sequence, double* timestamp_s) override;

 private:
  FrameSource& source_;
  const std::atomic<bool>* stop_;
  RgbdImage staging_;
  bool staged_ = false;
  int64_t staged_t_ns_ = 0;
  int64_t last_t_ns_ = 0;  // an error is "recorded" at the previous frame's time
  Status error_;
};

}  // namespace plumb

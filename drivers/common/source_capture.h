#pragma once
// SourceCapture: any FrameSource as the runner's capture step (sensor/frame_capture.h). The next
// frame is read ahead with next() into a staging image in prepareNext(); take() swaps it into the
// slot's image (cv::Mat headers only), drop() forgets it. Every source works this way, live or
// replayed: a TUM folder decodes its next PNG pair ahead exactly as a camera's frame arrives ahead.
#include <cstdint>

#include "drivers/common/frame_source.h"
#include "sensor/frame_capture.h"

namespace plumb {

class SourceCapture final : public FrameCapture {
 public:
  explicit SourceCapture(FrameSource& source) : source_(source) {}

  const PinholeCamera& camera() const override { return source_.camera(); }

  bool prepareNext(int64_t* t_recorded_ns) override;
  Status take(RgbdImage& out) override;
  bool drop(uint64_t* sequence, double* timestamp_s) override;

 private:
  FrameSource& source_;
  RgbdImage staging_;
  bool staged_ = false;
  int64_t staged_t_ns_ = 0;
  int64_t last_t_ns_ = 0;  // an error is "recorded" at the previous frame's time
  Status error_;
};

}  // namespace plumb

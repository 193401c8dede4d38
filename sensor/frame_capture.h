#pragma once
// FrameCapture: the first step of a run (pipeline/run/odometry_run.h) as a sensor sees it.
// drivers/common/source_capture.h implements it over any FrameSource; the runner only sees this, so
// drivers/ and pipeline/ meet here, in the contract, and neither knows the other.
//
// A capture prepares its next frame EARLY, before the runner has decided to take it: a camera
// delivers a finished (decoded) frame at its timestamp, and a replay must do the same, so the decode
// happens while the capture thread would otherwise wait for the frame's due time. The runner then
// either takes the prepared frame into a slot or, in real-time mode with no free slot, drops it.
#include <cstdint>

#include "platform/status.h"
#include "sensor/camera.h"
#include "sensor/rgbd_image.h"

namespace plumb {

class FrameCapture {
 public:
  virtual ~FrameCapture() = default;
  // The camera the frames come from (the run builds its system for it).
  virtual const PinholeCamera& camera() const = 0;
  // Prepares the next frame (idempotent until take()/drop()) and reports its recorded time in
  // nanoseconds; false when the input has ended.
  virtual bool prepareNext(int64_t* t_recorded_ns) = 0;
  // Hands the prepared frame over by swapping buffers with `out` (no pixel copy: the capture
  // refills the buffers it got back next time). A source error is returned here, so it travels
  // down the pipeline behind the frames before it.
  virtual Status take(RgbdImage& out) = 0;
  // Forgets the prepared frame (the runner dropped it); says which frame it was. false when the
  // prepared "frame" was an error, which has no place in the output.
  virtual bool drop(uint64_t* sequence, double* timestamp_s) = 0;
};

}  // namespace plumb

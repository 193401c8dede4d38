#pragma once
// ViewerSink: an OdometrySink decorator (pipeline/run/odometry_run.h) that hands every call to the
// sink it wraps (the run's outputs, unchanged) and copies what a viewer shows into a RunFeed
// (viewer/run_feed.h). What it adds to the run's threads, all into preallocated storage:
//   onPose (track):        one clock read and two atomic stores
//   onFrame (map):         one ring record
//   onFinishedFrame (map): one ring record
//   onFrameView (map):     the local map's positions when its version changed (~60 KB, per
//                          keyframe), a box-downscaled colour image when the server wants one (at
//                          most 10 a second, ~0.1 ms each), a ring record per accepted loop
// No allocation, no lock, no system call: tests/viewer/viewer_sink_test.cpp counts them.
#include <cstdint>

#include "pipeline/run/odometry_run.h"
#include "viewer/run_feed.h"

namespace plumb::viewer {

class ViewerSink final : public OdometrySink {
 public:
  // Both must outlive the sink.
  ViewerSink(OdometrySink& inner, RunFeed& feed) : inner_(inner), feed_(feed) {}

  Status begin(const OdometrySystem& system) override { return inner_.begin(system); }
  void onPose(const FrameOutput& frame) override;
  Status onFrame(const FrameOutput& frame) override;
  Status onFinishedFrame(const FinishedFrame& frame) override;
  Status onRetiredKeyframe(const RetiredKeyframe& keyframe) override { return inner_.onRetiredKeyframe(keyframe); }
  void onFrameView(const FrameView& view) override;

 private:
  void copyMap(const FrameView& view);
  void copyImage(const FrameView& view);

  OdometrySink& inner_;
  RunFeed& feed_;
  // Map thread.
  uint64_t map_version_seen_ = 0;
  uint64_t loops_seen_ = 0;
  uint64_t images_published_ = 0;
  int64_t last_image_ns_ = 0;
};

// Box-downscales a BGR image (CV_8UC3) by the smallest integer factor that fits FeedImage's
// bounds, into `out` (no allocation). False when the image is empty or not 8-bit BGR.
bool downscaleInto(const cv::Mat& bgr, FeedImage* out);

}  // namespace plumb::viewer

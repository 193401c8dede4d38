#pragma once
// V4l2Source: RGB-D frames from a UVC colour node (YUYV, MJPEG or GREY) paired with a depth node
// (Z16, as RealSense-class cameras expose depth over UVC) by timestamp. Without a depth node the
// depth image is all zeros ("no reading") and the source says so in describe().
//
// Pairing: by the buffers' kernel timestamps (CLOCK_MONOTONIC, checked per buffer: see
// timestampOnMonotonicClock). Hold one buffer of each node; when their timestamps differ by more
// than half the frame period the nodes keep (at least max_pair_dt_ns), give back the older one and
// take the next from that node. Unpaired frames are counted. Depth may come as Z16 or Y16 (same layout). V4L2 reports no intrinsics, so the
// camera comes from a camera file or preset.
#include <cstdint>
#include <memory>
#include <string>

#include "drivers/common/frame_source.h"
#include "drivers/v4l2/v4l2_capture.h"

namespace plumb {

struct V4l2SourceOptions {
  std::string colour_device = "/dev/video0";
  std::string depth_device;  // empty: colour only (depth zeros)
  V4l2PixelFormat colour_format = V4l2PixelFormat::kYuyv;
  int fps = 30;
  int buffer_count = 4;
  int poll_timeout_ms = 100;
  // Pairing window: half the frame period the streams keep (observed), at least this: 16 ms is
  // half a frame at 30 Hz. A closer pair is the same instant, a farther one is not.
  int64_t max_pair_dt_ns = 16'000'000;
  // Z16 units per metre: 1000 for millimetre depth (RealSense default depth unit).
  double depth_factor = 1000.0;
};

struct V4l2PairingStats {
  uint64_t pairs = 0;
  uint64_t unpaired_colour = 0;  // colour frames given back without a depth partner
  uint64_t unpaired_depth = 0;
  uint64_t undecodable = 0;      // MJPEG frames that did not decode
};

class V4l2Source : public FrameSource {
 public:
  // Opens both nodes at camera.width x camera.height. `device` is the system seam (tests: fake).
  static Status open(const V4l2SourceOptions& options, const PinholeCamera& camera,
                     V4l2Device& device, std::unique_ptr<V4l2Source>* out);

  SourceResult next(RgbdImage& out) override;
  const PinholeCamera& camera() const override { return camera_; }
  std::string describe() const override;
  const Status& lastError() const override { return error_; }
  Status reopen() override;
  bool isLive() const override { return true; }
  // "v4l2: pairs N, unpaired colour N, unpaired depth N, undecodable N, error buffers N,
  // dequeue-time stamps N[, depth format z16|y16]".
  std::string healthReport() const override;

  const V4l2PairingStats& pairingStats() const { return stats_; }

 private:
  explicit V4l2Source(V4l2Device& device) : colour_(device), depth_(device) {}
  Status openNodes();
  SourceResult fail(const Status& error);
  bool convert(RgbdImage& out);
  int64_t pairWindowNs() const;

  V4l2SourceOptions options_;
  PinholeCamera camera_;
  V4l2Capture colour_, depth_;
  V4l2FrameView colour_view_, depth_view_;
  bool holding_colour_ = false, holding_depth_ = false;
  Status error_;
  // Output sequence numbers: continue across reopen, with frames lost meanwhile estimated from
  // the time gap, so supervision sees the loss as a sequence gap.
  bool have_last_ = false;
  uint64_t last_sequence_ = 0;
  int64_t last_timestamp_ns_ = 0;
  uint32_t last_driver_sequence_ = 0;
  bool reopened_ = false;
  V4l2PairingStats stats_;
};

}  // namespace plumb

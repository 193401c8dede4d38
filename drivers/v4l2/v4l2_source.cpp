#include "drivers/v4l2/v4l2_source.h"

#include <cmath>
#include <cstdlib>

#include "drivers/v4l2/pixel_formats.h"

namespace plumb {
namespace {
// Pairing attempts per next(): each gives back one buffer, so a few frames of skew resolve.
constexpr int kMaxPairingSteps = 8;
}  // namespace

Status V4l2Source::open(const V4l2SourceOptions& options, const PinholeCamera& camera,
                        V4l2Device& device, std::unique_ptr<V4l2Source>* out) {
  const std::string problem = camera.validate();
  if (!problem.empty()) return Status::Error("v4l2:" + options.colour_device + ": camera invalid: " + problem);
  if (options.colour_format == V4l2PixelFormat::kZ16 || options.colour_format == V4l2PixelFormat::kY16)
    return Status::Error("v4l2:" + options.colour_device + ": " + pixelFormatName(options.colour_format) +
                         " is a depth format, not colour");
  std::unique_ptr<V4l2Source> source(new V4l2Source(device));
  source->options_ = options;
  source->camera_ = camera;
  source->camera_.depth_factor = options.depth_factor;
  PLUMB_RETURN_IF_ERROR(source->openNodes());
  *out = std::move(source);
  return Status::Ok();
}

Status V4l2Source::openNodes() {
  holding_colour_ = holding_depth_ = false;
  V4l2CaptureOptions c;
  c.device_path = options_.colour_device;
  c.format = options_.colour_format;
  c.width = camera_.width;
  c.height = camera_.height;
  c.fps = options_.fps;
  c.buffer_count = options_.buffer_count;
  c.poll_timeout_ms = options_.poll_timeout_ms;
  PLUMB_RETURN_IF_ERROR(colour_.open(c));
  if (!options_.depth_device.empty()) {
    V4l2CaptureOptions d = c;
    d.device_path = options_.depth_device;
    d.format = V4l2PixelFormat::kZ16;
    d.width = camera_.depthWidth();  // an unregistered depth camera has its own size
    d.height = camera_.depthHeight();
    const Status st = depth_.open(d);
    if (!st.ok()) {
      colour_.close();
      return st;
    }
  }
  return Status::Ok();
}

int64_t V4l2Source::pairWindowNs() const {
  // Half the frame period the streams keep (16 ms at 30 Hz): a closer pair is the same instant,
  // and no frame of the other stream can be closer; never below the configured minimum.
  double period_ns = colour_.observedPeriodNs();
  if (depth_.observedPeriodNs() > 0 && (period_ns <= 0 || depth_.observedPeriodNs() < period_ns))
    period_ns = depth_.observedPeriodNs();
  return std::max<int64_t>(options_.max_pair_dt_ns, int64_t(period_ns / 2));
}

std::string V4l2Source::healthReport() const {
  const V4l2CaptureCounters& c = colour_.counters();
  const V4l2CaptureCounters& d = depth_.counters();
  std::string text = "v4l2: pairs " + std::to_string(stats_.pairs) + ", unpaired colour " +
                     std::to_string(stats_.unpaired_colour) + ", unpaired depth " +
                     std::to_string(stats_.unpaired_depth) + ", undecodable " + std::to_string(stats_.undecodable) +
                     ", error buffers " + std::to_string(c.error_buffers + d.error_buffers) +
                     ", dequeue-time stamps " + std::to_string(c.dequeue_time_stamps + d.dequeue_time_stamps);
  if (!options_.depth_device.empty() && depth_.isOpen())
    text += std::string(", depth format ") + pixelFormatName(depth_.format());
  return text;
}

std::string V4l2Source::describe() const {
  return "v4l2:" + options_.colour_device +
         (options_.depth_device.empty() ? " (colour only, no depth)" : "," + options_.depth_device);
}

SourceResult V4l2Source::fail(const Status& error) {
  error_ = error;
  // The nodes are unusable until reopen(); closing now also releases the mapped buffers.
  colour_.close();
  depth_.close();
  holding_colour_ = holding_depth_ = false;
  return SourceResult::kError;
}

Status V4l2Source::reopen() {
  colour_.close();
  depth_.close();
  const Status st = openNodes();
  if (st.ok()) {
    reopened_ = true;
    error_ = Status::Ok();
  }
  return st;
}

SourceResult V4l2Source::next(RgbdImage& out) {
  if (!colour_.isOpen()) return fail(error_.ok() ? Status::Error(describe() + ": not open") : error_);
  const bool paired_mode = !options_.depth_device.empty();
  for (int step = 0; step < kMaxPairingSteps; ++step) {
    Status error;
    if (!holding_colour_) {
      const SourceResult r = colour_.dequeue(&colour_view_, &error);
      if (r == SourceResult::kError) return fail(error);
      if (r != SourceResult::kFrame) return r;
      holding_colour_ = true;
    }
    if (paired_mode && !holding_depth_) {
      const SourceResult r = depth_.dequeue(&depth_view_, &error);
      if (r == SourceResult::kError) return fail(error);
      if (r != SourceResult::kFrame) return r;  // keep the colour buffer for the next call
      holding_depth_ = true;
    }
    const int64_t dt_ns = paired_mode ? colour_view_.timestamp_ns - depth_view_.timestamp_ns : 0;
    if (std::llabs(dt_ns) <= pairWindowNs()) {
      const bool converted = convert(out);
      holding_colour_ = holding_depth_ = false;
      Status st = colour_.requeue();
      if (st.ok() && paired_mode) st = depth_.requeue();
      if (!st.ok()) return fail(st);
      if (!converted) {
        ++stats_.undecodable;
        continue;
      }
      ++stats_.pairs;
      return SourceResult::kFrame;
    }
    // Give back the older buffer and try its successor.
    const bool colour_is_older = dt_ns < 0;
    const Status st = colour_is_older ? colour_.requeue() : depth_.requeue();
    if (!st.ok()) return fail(st);
    if (colour_is_older) {
      holding_colour_ = false;
      ++stats_.unpaired_colour;
    } else {
      holding_depth_ = false;
      ++stats_.unpaired_depth;
    }
  }
  return SourceResult::kNoFrame;
}

bool V4l2Source::convert(RgbdImage& out) {
  const int w = camera_.width, h = camera_.height;
  const V4l2FrameView& c = colour_view_;
  switch (options_.colour_format) {
    case V4l2PixelFormat::kYuyv:
      if (c.bytes_used < c.stride * h) return false;
      yuyvToBgr(c.data, w, h, c.stride, out.bgr);
      break;
    case V4l2PixelFormat::kGrey:
      if (c.bytes_used < c.stride * h) return false;
      greyToBgr(c.data, w, h, c.stride, out.bgr);
      break;
    case V4l2PixelFormat::kMjpeg:
      if (!mjpegToBgr(c.data, c.bytes_used, w, h, out.bgr)) return false;
      break;
    case V4l2PixelFormat::kZ16:
    case V4l2PixelFormat::kY16:
      return false;
  }
  const int dw = camera_.depthWidth(), dh = camera_.depthHeight();
  if (options_.depth_device.empty()) {
    out.depth_raw.create(dh, dw, CV_16UC1);
    out.depth_raw.setTo(0);
    out.depth_timestamp_s = c.timestamp_ns * 1e-9;
  } else {
    if (depth_view_.bytes_used < depth_view_.stride * dh) return false;
    z16ToDepth(depth_view_.data, dw, dh, depth_view_.stride, out.depth_raw);
    out.depth_timestamp_s = depth_view_.timestamp_ns * 1e-9;
  }
  // Sequence: driver counter differences within a session; across a reopen, the time gap.
  uint64_t step = 1;
  if (have_last_ && reopened_) {
    // The frame period the camera really kept (a camera may run slower than asked), else the
    // nominal one.
    const double period_ns = colour_.observedPeriodNs() > 0 ? colour_.observedPeriodNs() : 1e9 / options_.fps;
    step = static_cast<uint64_t>(
        std::max(1.0, std::round((c.timestamp_ns - last_timestamp_ns_) / period_ns)));
  } else if (have_last_) {
    // Modulo 2^32: the driver's counter wraps (vivid's "Wrap Sequence Number" tests exactly that).
    // A step of 0 or one that looks backwards (over half the range) is a restarted counter.
    const uint32_t driver_step = c.sequence - last_driver_sequence_;
    if (driver_step > 0 && driver_step < 0x80000000u) step = driver_step;
    // A camera cannot have made more frames than fit in the time between the two stamps (at up to
    // twice the rate it kept): a larger jump is a counter that restarted (v4l2loopback numbers the
    // first frame after a reader's VIDIOC_REQBUFS 0), not lost frames.
    const int64_t elapsed_ns = c.timestamp_ns - last_timestamp_ns_;
    const double period_ns = colour_.observedPeriodNs();
    if (period_ns > 0 && elapsed_ns > 0)
      step = std::min<uint64_t>(step, std::max<uint64_t>(1, uint64_t(2.0 * elapsed_ns / period_ns)));
  }
  out.sequence = have_last_ ? last_sequence_ + step : 0;
  have_last_ = true;
  reopened_ = false;
  last_sequence_ = out.sequence;
  last_timestamp_ns_ = c.timestamp_ns;
  last_driver_sequence_ = c.sequence;
  out.timestamp_s = c.timestamp_ns * 1e-9;
  out.t_sensor_ns = c.timestamp_ns;
  out.depth_factor = options_.depth_factor;
  return true;
}

}  // namespace plumb

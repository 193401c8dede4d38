// plumb::api::Odometry: the public push-style odometry over a RunSession (pipeline/run/run_session.h:
// the runner's stages and end-of-run protocol, stepped lock-step). Copies the caller's frame into
// the session's slot, steps, and queues finished poses.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>

#include "api/api_convert.h"
#include "api/plumb/odometry.h"
#include "drivers/dataset/camera_presets.h"
#include "pipeline/run/run_session.h"
#include "sensor/rgbd_image.h"

namespace plumb::api {

const char* toString(TrackingState state) {
  switch (state) {
    case TrackingState::kOk: return "ok";
    case TrackingState::kWeak: return "weak";
    case TrackingState::kLost: return "lost";
    case TrackingState::kNotInitialized: break;
  }
  return "not_initialized";
}

Status resolveCamera(const CameraSpec& spec, CameraValues* out) {
  PinholeCamera camera;
  if (spec.use_values) {
    camera = toCamera(spec.values);
    const std::string problem = camera.validate();
    if (!problem.empty()) return Status::Error("camera values: " + problem);
  } else {
    if (spec.name_or_file.empty()) return Status::Error("camera: give a preset (tum1 tum2 tum3 icl), a file or values");
    const ::plumb::Status st = cameraFromSpec(spec.name_or_file, &camera);
    if (!st.ok()) return fromStatus(st);
    // CameraValues (the installed header) has no depth camera: taking such a file would read
    // unregistered depth as registered.
    if (!camera.depthRegistered()) {
      return Status::Error(spec.name_or_file + ": describes a depth camera not registered to colour; the API takes "
                           "registered depth only (`plumb run` registers it)");
    }
  }
  *out = toValues(camera);
  return Status::Ok();
}

namespace {

// Finished poses wait here until popFinished(): a ring allocated once with room for the output
// delay and a margin, so a caller who drains after every track() never makes it grow.
class FinishedQueue final : public OdometrySink {
 public:
  // A pose finishes output_delay frames after it was tracked (at finish() all of them at once).
  ::plumb::Status begin(const OdometrySystem& system) override {
    ring_.assign(std::size_t(system.options().output_delay_frames) + 64, FinishedPose{});
    return ::plumb::Status::Ok();
  }
  ::plumb::Status onFinishedFrame(const FinishedFrame& frame) override {
    if (count_ == ring_.size()) grow();
    ring_[(head_ + count_) % ring_.size()] = toFinished(frame);
    ++count_;
    return ::plumb::Status::Ok();
  }
  bool pop(FinishedPose* out) {
    if (count_ == 0) return false;
    *out = ring_[head_];
    head_ = (head_ + 1) % ring_.size();
    --count_;
    return true;
  }

 private:
  // Only when the caller does not drain: keeps every pose, in order.
  void grow() {
    std::vector<FinishedPose> bigger(ring_.size() * 2);
    for (std::size_t i = 0; i < count_; ++i) bigger[i] = ring_[(head_ + i) % ring_.size()];
    ring_.swap(bigger);
    head_ = 0;
  }
  std::vector<FinishedPose> ring_ = std::vector<FinishedPose>(1);  // begin() sizes it
  std::size_t head_ = 0, count_ = 0;
};

}  // namespace

struct Odometry::Impl {
  CameraValues camera;
  std::unique_ptr<FinishedQueue> finished;
  std::unique_ptr<RunSession> session;
  bool finished_input = false;
  bool has_previous_timestamp = false;
  double previous_timestamp_s = 0;
};

Odometry::Odometry(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Odometry::~Odometry() = default;

Status Odometry::create(const OdometryConfig& config, std::unique_ptr<Odometry>* out) {
  auto impl = std::make_unique<Impl>();
  Status st = resolveCamera(config.camera, &impl->camera);
  if (!st.ok) return st;
  const SystemOptions options = systemOptions(config.lines, config.line_samples, config.output_delay_frames);
  impl->finished = std::make_unique<FinishedQueue>();
  // The runner's default options (deterministic, loop closing with its defaults): the same bytes
  // as `plumb run`.
  OdometryRunOptions run_options;
  run_options.loop_closing = config.loop_closing;
  // Warm-up far away: the allocation bookkeeping is the runner's; callers measure themselves.
  run_options.warmup_frames = UINT64_MAX;
  st = fromStatus(
      RunSession::create(toCamera(impl->camera), options, *impl->finished, run_options, &impl->session));
  if (!st.ok) return st;
  out->reset(new Odometry(std::move(impl)));
  return Status::Ok();
}

const CameraValues& Odometry::camera() const { return impl_->camera; }

namespace {

std::string stampText(double t) {
  char text[40];
  std::snprintf(text, sizeof text, "%.9g", t);
  return text;
}

// The rules of every other way in (TUM lists, recordings): finite, 0..1e10 s, strictly increasing.
Status checkTimestamp(double t, bool has_previous, double previous) {
  if (!std::isfinite(t) || t < 0) return Status::Error("frame: timestamp " + stampText(t) + " is not a finite non-negative number");
  if (t > kMaxTimestampS) {
    return Status::Error("frame: timestamp " + stampText(t) + " is beyond 1e10 s (the year 2286): seconds are expected");
  }
  if (has_previous && !(t > previous)) {
    return Status::Error(std::string("frame: timestamp ") + stampText(t) + (t == previous ? " repeats" : " goes back from") +
                         " the previous frame's " + stampText(previous) + " (timestamps must increase)");
  }
  return Status::Ok();
}

Status checkFrame(const FrameView& f, const CameraValues& camera) {
  if (f.color == nullptr || f.depth == nullptr) return Status::Error("frame: colour and depth are required");
  if (f.width != camera.width || f.height != camera.height) {
    return Status::Error("frame: image is " + std::to_string(f.width) + "x" + std::to_string(f.height) +
                         ", the camera is " + std::to_string(camera.width) + "x" + std::to_string(camera.height));
  }
  if (f.color_stride != 0 && f.color_stride < std::size_t(f.width) * 3) return Status::Error("frame: colour stride too small");
  if (f.depth_stride != 0 && f.depth_stride < std::size_t(f.width) * 2) return Status::Error("frame: depth stride too small");
  return Status::Ok();
}

}  // namespace

Status Odometry::track(const FrameView& frame, TrackOutput* out) {
  if (impl_->finished_input) return Status::Error("track() after finish()");
  Status st = checkFrame(frame, impl_->camera);
  if (st.ok) st = checkTimestamp(frame.timestamp_s, impl_->has_previous_timestamp, impl_->previous_timestamp_s);
  if (!st.ok) return st;
  impl_->has_previous_timestamp = true;
  impl_->previous_timestamp_s = frame.timestamp_s;
  RgbdImage& image = impl_->session->slot().image;
  const int w = frame.width, h = frame.height;
  const std::size_t color_stride = frame.color_stride ? frame.color_stride : std::size_t(w) * 3;
  const std::size_t depth_stride = frame.depth_stride ? frame.depth_stride : std::size_t(w) * 2;
  for (int y = 0; y < h; ++y) {
    const uint8_t* src = frame.color + std::size_t(y) * color_stride;
    uint8_t* dst = image.bgr.ptr<uint8_t>(y);
    if (frame.format == PixelFormat::kBgr) {
      std::memcpy(dst, src, std::size_t(w) * 3);
    } else {
      for (int x = 0; x < w; ++x) {
        dst[3 * x] = src[3 * x + 2];
        dst[3 * x + 1] = src[3 * x + 1];
        dst[3 * x + 2] = src[3 * x];
      }
    }
    std::memcpy(image.depth_raw.ptr<uint16_t>(y), reinterpret_cast<const uint8_t*>(frame.depth) + std::size_t(y) * depth_stride,
                std::size_t(w) * 2);
  }
  image.timestamp_s = frame.timestamp_s;
  image.depth_timestamp_s = frame.timestamp_s;
  st = fromStatus(impl_->session->step());
  if (!st.ok) return st;
  if (out != nullptr) toTrackOutput(impl_->session->slot().tracked->output, out);
  return Status::Ok();
}

bool Odometry::popFinished(FinishedPose* out) { return impl_->finished->pop(out); }

Status Odometry::finish() {
  if (impl_->finished_input) return Status::Ok();
  impl_->finished_input = true;
  return fromStatus(impl_->session->finish());
}

Counters Odometry::counters() const {
  return toCounters(impl_->session->system().stats(), impl_->session->frames(), impl_->session->extractionFailures());
}

}  // namespace plumb::api

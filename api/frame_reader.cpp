// plumb::api::FrameReader: frames of plumb's own sources (TUM folders through the dataset driver,
// synthetic scenes) as plain buffers, for examples, notebooks (the Python module) and tests.
#include <cstring>
#include <memory>

#include "api/api_convert.h"
#include "api/plumb/odometry.h"
#include "drivers/open/open_source.h"
#include "drivers/synth/synth_spec.h"
#include "drivers/synth/synthetic_scene.h"

namespace plumb::api {

struct FrameReader::Impl {
  std::unique_ptr<FrameSource> source;
  CameraValues camera;
  RgbdImage image;
};

FrameReader::FrameReader(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
FrameReader::~FrameReader() = default;

Status FrameReader::open(const std::string& spec, const std::string& camera, std::unique_ptr<FrameReader>* out) {
  auto impl = std::make_unique<Impl>();
  const Status st = fromStatus(openFrameSource(spec, camera, &impl->source));
  if (!st.ok) return st;
  // Its frames would go to Odometry as registered depth with a camera that cannot say otherwise.
  if (!impl->source->camera().depthRegistered()) {
    return Status::Error(impl->source->describe() +
                         ": its depth is not registered to colour (the camera describes a depth camera); the API "
                         "takes registered depth only (`plumb run` registers it)");
  }
  impl->camera = toValues(impl->source->camera());
  out->reset(new FrameReader(std::move(impl)));
  return Status::Ok();
}

const CameraValues& FrameReader::camera() const { return impl_->camera; }
std::size_t FrameReader::frameCount() const { return impl_->source->frameCount(); }

Status FrameReader::next(std::vector<uint8_t>* bgr, std::vector<uint16_t>* depth, double* timestamp_s, bool* got) {
  *got = false;
  RgbdImage& image = impl_->image;
  switch (impl_->source->next(image)) {
    case SourceResult::kFrame: break;
    case SourceResult::kEndOfStream: return Status::Ok();
    case SourceResult::kNoFrame: return Status::Error(impl_->source->describe() + ": no frame (timeout)");
    case SourceResult::kError: return fromStatus(impl_->source->lastError());
  }
  const int w = image.bgr.cols, h = image.bgr.rows;
  if (image.depth_raw.cols != w || image.depth_raw.rows != h) return Status::Error("colour and depth sizes differ");
  bgr->resize(std::size_t(w) * h * 3);
  depth->resize(std::size_t(w) * h);
  for (int y = 0; y < h; ++y) {
    std::memcpy(bgr->data() + std::size_t(y) * w * 3, image.bgr.ptr<uint8_t>(y), std::size_t(w) * 3);
    std::memcpy(depth->data() + std::size_t(y) * w, image.depth_raw.ptr<uint16_t>(y), std::size_t(w) * 2);
  }
  *timestamp_s = image.timestamp_s;
  *got = true;
  return Status::Ok();
}

std::vector<FinishedPose> FrameReader::groundTruth(long frames) const {
  std::vector<FinishedPose> poses;
  const auto* synth = dynamic_cast<const SyntheticSource*>(impl_->source.get());
  if (synth == nullptr) return poses;
  for (const StampedPose& p : syntheticGroundTruth(synth->scene(), frames)) poses.push_back(toFinished(p));
  for (std::size_t i = 0; i < poses.size(); ++i) poses[i].sequence = i;
  return poses;
}

}  // namespace plumb::api

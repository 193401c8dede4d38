// SyntheticSource: a SyntheticScene delivered frame after frame through the FrameSource interface.
#include <chrono>

#include "drivers/synth/synthetic_scene.h"

namespace plumb {

SyntheticSource::SyntheticSource(std::unique_ptr<SyntheticScene> scene) : scene_(std::move(scene)) {}

Status SyntheticSource::create(const SynthOptions& options, std::unique_ptr<SyntheticSource>* out) {
  std::unique_ptr<SyntheticScene> scene;
  PLUMB_RETURN_IF_ERROR(SyntheticScene::create(options, &scene));
  out->reset(new SyntheticSource(std::move(scene)));
  return Status::Ok();
}

SourceResult SyntheticSource::next(RgbdImage& out) {
  if (next_index_ >= scene_->numFrames()) return SourceResult::kEndOfStream;
  last_error_ = scene_->render(next_index_, out);
  if (!last_error_.ok()) return SourceResult::kError;
  out.t_sensor_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                        std::chrono::steady_clock::now().time_since_epoch())
                        .count();
  ++next_index_;
  return SourceResult::kFrame;
}

const PinholeCamera& SyntheticSource::camera() const { return scene_->camera(); }

std::string SyntheticSource::describe() const {
  return "synth:" + scene_->options().preset + ":seed=" + std::to_string(scene_->options().seed);
}

const Status& SyntheticSource::lastError() const { return last_error_; }

}  // namespace plumb

#pragma once
// ForwardingSource: a FrameSource that passes every call to the source it wraps. Wrappers
// (SkipFramesSource, the hot-plug listener of live specs) derive from it and override only what
// they change, so a new FrameSource call (a stop flag, a hot-plug hint) reaches every wrapped source.
#include <atomic>
#include <memory>
#include <string>

#include "drivers/common/frame_source.h"

namespace plumb {

class ForwardingSource : public FrameSource {
 public:
  explicit ForwardingSource(std::unique_ptr<FrameSource> inner) : inner_(std::move(inner)) {}

  SourceResult next(RgbdImage& out) override { return inner_->next(out); }
  const PinholeCamera& camera() const override { return inner_->camera(); }
  std::string describe() const override { return inner_->describe(); }
  const Status& lastError() const override { return inner_->lastError(); }
  Status reopen() override { return inner_->reopen(); }
  bool isLive() const override { return inner_->isLive(); }
  std::size_t frameCount() const override { return inner_->frameCount(); }
  SourceDamage damage() const override { return inner_->damage(); }
  std::string healthReport() const override { return inner_->healthReport(); }
  void setStopFlag(const std::atomic<bool>* stop) override { inner_->setStopFlag(stop); }
  void wakeReconnect() override { inner_->wakeReconnect(); }
  void deviceLeft() override { inner_->deviceLeft(); }
  bool supervision(SourceSupervision* out) const override { return inner_->supervision(out); }

 protected:
  std::unique_ptr<FrameSource> inner_;
};

}  // namespace plumb

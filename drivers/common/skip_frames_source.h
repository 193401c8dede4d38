#pragma once
// SkipFramesSource: starts a finite source at frame N (`plumb run --skip-frames N`): the first N
// frames are read and discarded on the first next(), so the run's first frame is the source's
// frame N (its own timestamps are kept). Nothing of the skipped frames reaches the pipeline or
// the trajectory. Errors while skipping end the run like any read error. A source with fewer
// frames ends at once.
#include <cstdint>
#include <memory>

#include "drivers/common/forwarding_source.h"

namespace plumb {

class SkipFramesSource : public ForwardingSource {
 public:
  SkipFramesSource(std::unique_ptr<FrameSource> inner, uint64_t skip) : ForwardingSource(std::move(inner)), skip_(skip) {}

  SourceResult next(RgbdImage& out) override {
    // A source that knows its length ends at once when everything is skipped: nothing is read,
    // so --skip-frames 10000000 over a 300-frame scene costs nothing.
    const std::size_t known = inner_->frameCount();
    if (known > 0 && skip_ >= known) return SourceResult::kEndOfStream;
    while (skipped_ < skip_) {
      const SourceResult r = inner_->next(out);
      if (r == SourceResult::kNoFrame) continue;
      if (r != SourceResult::kFrame) return r;
      ++skipped_;
    }
    return inner_->next(out);
  }
  std::string describe() const override { return inner_->describe() + " from frame " + std::to_string(skip_); }
  std::size_t frameCount() const override {
    const std::size_t n = inner_->frameCount();
    return n > skip_ ? n - std::size_t(skip_) : 0;
  }

 private:
  uint64_t skip_;
  uint64_t skipped_ = 0;
};

}  // namespace plumb

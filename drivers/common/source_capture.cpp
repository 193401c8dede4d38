#include "drivers/common/source_capture.h"

#include <cmath>
#include <utility>

namespace plumb {

bool SourceCapture::prepareNext(int64_t* t_recorded_ns) {
  if (staged_) {
    *t_recorded_ns = staged_t_ns_;
    return true;
  }
  for (;;) {
    const SourceResult r = source_.next(staging_);
    if (r == SourceResult::kEndOfStream) return false;
    if (r == SourceResult::kNoFrame) {  // a live source's timeout: ask again, unless told to stop
      if (stop_ != nullptr && stop_->load(std::memory_order_relaxed)) return false;
      continue;
    }
    staged_ = true;
    if (r == SourceResult::kError) {
      error_ = source_.lastError().withContext(source_.describe());
      staged_t_ns_ = last_t_ns_;
    } else {
      error_ = Status::Ok();
      staged_t_ns_ = std::llround(staging_.timestamp_s * 1e9);
      last_t_ns_ = staged_t_ns_;
    }
    *t_recorded_ns = staged_t_ns_;
    return true;
  }
}

Status SourceCapture::take(RgbdImage& out) {
  staged_ = false;
  if (!error_.ok()) return error_;
  std::swap(out, staging_);
  return Status::Ok();
}

bool SourceCapture::drop(uint64_t* sequence, double* timestamp_s) {
  staged_ = false;
  if (!error_.ok()) return false;
  *sequence = staging_.sequence;
  *timestamp_s = staging_.timestamp_s;
  return true;
}

}  // namespace plumb

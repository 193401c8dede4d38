#include "drivers/fault/resilient_source.h"

#include <algorithm>
#include <cstdio>

namespace plumb {
namespace {

const char* eventName(SourceEventKind kind) {
  switch (kind) {
    case SourceEventKind::kError: return "error";
    case SourceEventKind::kStallTimeout: return "stall timeout";
    case SourceEventKind::kReopenFailed: return "reopen failed";
    case SourceEventKind::kReconnected: return "reconnected";
    case SourceEventKind::kGaveUp: return "gave up";
    case SourceEventKind::kGap: return "frames missing";
    case SourceEventKind::kWoken: return "woken by a hot-plug arrival";
    case SourceEventKind::kDeparted: return "usb camera left (libusb hot-plug)";
  }
  return "?";
}

}  // namespace

ResilientSource::ResilientSource(std::unique_ptr<FrameSource> inner,
                                 const ResilientSourceOptions& options, SourceClock& clock)
    : inner_(std::move(inner)), options_(options), clock_(clock) {
  last_frame_ns_ = clock_.nowNs();
}

void ResilientSource::record(SourceEventKind kind, uint64_t frames) {
  if (!stats_.events.push_back(SourceEvent{clock_.nowNs(), kind, frames, last_sequence_}))
    ++stats_.events_dropped;
}

SourceResult ResilientSource::next(RgbdImage& out) {
  // Each failure gets one full round of reopen attempts; a source that fails again straight
  // after every successful reopen is bounded by the same budget.
  for (int round = 0; round <= std::max(options_.max_reopen_attempts, 1); ++round) {
    // The camera left the bus (libusb said so): a disconnect now, even if the driver has not
    // noticed yet or the last frames are still queued.
    if (departed_.load(std::memory_order_relaxed) && departed_.exchange(false, std::memory_order_relaxed)) {
      ++stats_.usb_departures;
      stats_.last_error = inner_->describe() + ": the USB camera left the bus";
      record(SourceEventKind::kDeparted);
      if (!recover()) return stopRequested() ? SourceResult::kNoFrame : SourceResult::kError;
      continue;
    }
    const SourceResult r = inner_->next(out);
    if (r == SourceResult::kFrame) {
      if (time_first_frame_) {
        stats_.arrival_to_frame_ns = clock_.nowNs() - arrival_ns_.load(std::memory_order_relaxed);
        time_first_frame_ = false;
      }
      if (have_last_sequence_ && out.sequence > last_sequence_ + 1) {
        const uint64_t missing = out.sequence - last_sequence_ - 1;
        stats_.frames_missing += missing;
        ++stats_.gaps;
        record(SourceEventKind::kGap, missing);
      }
      have_last_sequence_ = true;
      last_sequence_ = out.sequence;
      last_frame_ns_ = clock_.nowNs();
      ++stats_.frames_delivered;
      return r;
    }
    if (r == SourceResult::kEndOfStream) return r;
    if (r == SourceResult::kNoFrame) {
      ++stats_.no_frame_results;
      if (options_.stall_timeout_ns <= 0 || !inner_->isLive() ||
          clock_.nowNs() - last_frame_ns_ < options_.stall_timeout_ns)
        return r;
      ++stats_.stall_timeouts;
      stats_.last_error = inner_->describe() + ": no frame for " +
                          std::to_string((clock_.nowNs() - last_frame_ns_) / 1000000) + " ms";
      record(SourceEventKind::kStallTimeout);
      if (!recover()) return stopRequested() ? SourceResult::kNoFrame : SourceResult::kError;
      continue;
    }
    ++stats_.errors;
    stats_.last_error = inner_->lastError().message();
    record(SourceEventKind::kError);
    if (!inner_->isLive() || !recover()) {
      if (inner_->isLive() && stopRequested()) return SourceResult::kNoFrame;
      error_ = inner_->isLive() ? error_ : inner_->lastError();
      return SourceResult::kError;
    }
  }
  error_ = Status::Error(describe() + ": source keeps failing right after every reopen");
  return SourceResult::kError;
}

void ResilientSource::wakeReconnect() {
  arrival_ns_.store(clock_.nowNs(), std::memory_order_relaxed);
  wake_.store(true, std::memory_order_relaxed);
  absent_.store(false, std::memory_order_release);  // a waiter that sees this sees the two above
}

void ResilientSource::deviceLeft() {
  absent_.store(true, std::memory_order_relaxed);
  departed_.store(true, std::memory_order_relaxed);
}

void ResilientSource::noteWoken() {
  ++stats_.hotplug_wakeups;
  record(SourceEventKind::kWoken);
  woken_ = true;
}

void ResilientSource::sleepBackoff(int64_t backoff_ns) {
  if (options_.wake_slice_ns <= 0) {
    clock_.sleepForNs(backoff_ns);
    return;
  }
  const int64_t until_ns = clock_.nowNs() + backoff_ns;
  for (int64_t now_ns = clock_.nowNs(); now_ns < until_ns; now_ns = clock_.nowNs()) {
    if (wake_.exchange(false, std::memory_order_relaxed)) {
      noteWoken();
      return;
    }
    if (stopRequested()) return;
    clock_.sleepForNs(std::min(options_.wake_slice_ns, until_ns - now_ns));
  }
}

void ResilientSource::waitForArrival(int64_t failed_at_ns) {
  if (options_.wake_slice_ns <= 0) return;
  bool waited = false;
  while (absent_.load(std::memory_order_acquire)) {
    if (stopRequested()) return;
    if (options_.absent_wait_ns > 0 && clock_.nowNs() - failed_at_ns >= options_.absent_wait_ns) return;
    waited = true;
    clock_.sleepForNs(options_.wake_slice_ns);
  }
  if (waited && wake_.exchange(false, std::memory_order_relaxed)) noteWoken();
}

bool ResilientSource::recover() {
  const int64_t failed_at_ns = clock_.nowNs();
  ++stats_.outages;
  wake_.store(false, std::memory_order_relaxed);  // arrivals before the failure say nothing
  woken_ = false;
  time_first_frame_ = false;
  const auto end_outage = [&] {
    const int64_t outage_ns = clock_.nowNs() - failed_at_ns;
    stats_.time_disconnected_ns += outage_ns;
    stats_.longest_outage_ns = std::max(stats_.longest_outage_ns, outage_ns);
  };
  int64_t backoff_ns = options_.initial_backoff_ns;
  for (int attempt = 1; options_.max_reopen_attempts == 0 || attempt <= options_.max_reopen_attempts;
       ++attempt) {
    waitForArrival(failed_at_ns);  // reopening a camera that is off the bus cannot succeed
    if (stopRequested()) {  // the run is ending: stop waiting for the camera
      end_outage();
      return false;
    }
    ++stats_.reopen_attempts;
    const Status st = inner_->reopen();
    if (st.ok()) {
      ++stats_.reconnects;
      end_outage();
      last_frame_ns_ = clock_.nowNs();
      // A departure heard while an error had already started this outage belongs to it.
      if (departed_.exchange(false, std::memory_order_relaxed)) ++stats_.usb_departures;
      time_first_frame_ = woken_;
      record(SourceEventKind::kReconnected, static_cast<uint64_t>(attempt));
      return true;
    }
    ++stats_.reopen_failures;
    stats_.last_error = st.message();
    record(SourceEventKind::kReopenFailed);
    sleepBackoff(backoff_ns);
    backoff_ns = std::min<int64_t>(options_.max_backoff_ns,
                                   static_cast<int64_t>(backoff_ns * options_.backoff_multiplier));
  }
  end_outage();
  record(SourceEventKind::kGaveUp);
  error_ = Status::Error(describe() + ": gave up after " +
                         std::to_string(options_.max_reopen_attempts) +
                         " reopen attempts; last error: " + stats_.last_error);
  return false;
}

bool ResilientSource::supervision(SourceSupervision* out) const {
  out->errors = stats_.errors;
  out->stall_timeouts = stats_.stall_timeouts;
  out->reconnects = stats_.reconnects;
  out->reopen_failures = stats_.reopen_failures;
  out->outages = stats_.outages;
  out->usb_departures = stats_.usb_departures;
  out->usb_arrivals = stats_.hotplug_wakeups;
  out->frames_missing = stats_.frames_missing;
  out->gaps = stats_.gaps;
  out->disconnected_ns = stats_.time_disconnected_ns;
  out->longest_outage_ns = stats_.longest_outage_ns;
  out->arrival_to_frame_ns = stats_.arrival_to_frame_ns;
  return true;
}

std::string ResilientSource::healthReport() const {
  char line[320];
  std::snprintf(line, sizeof line,
                "source: errors %llu, stall timeouts %llu, reconnects %llu (%.3f s disconnected, longest outage "
                "%.3f s, %llu failed reopens, usb departures %llu, hot-plug wake-ups %llu), frames missing %llu in "
                "%llu gaps",
                static_cast<unsigned long long>(stats_.errors), static_cast<unsigned long long>(stats_.stall_timeouts),
                static_cast<unsigned long long>(stats_.reconnects), stats_.time_disconnected_ns * 1e-9,
                stats_.longest_outage_ns * 1e-9, static_cast<unsigned long long>(stats_.reopen_failures),
                static_cast<unsigned long long>(stats_.usb_departures),
                static_cast<unsigned long long>(stats_.hotplug_wakeups),
                static_cast<unsigned long long>(stats_.frames_missing), static_cast<unsigned long long>(stats_.gaps));
  const std::string inner = inner_->healthReport();
  std::string text = inner.empty() ? std::string(line) : std::string(line) + "; " + inner;
  const std::string events = describeEvents();
  for (std::size_t start = 0; start < events.size();) {
    const std::size_t end = events.find('\n', start);
    text += "\n  " + events.substr(start, end - start);
    start = end == std::string::npos ? events.size() : end + 1;
  }
  return text;
}

std::string ResilientSource::describeEvents() const {
  std::string text;
  char line[160];
  for (const SourceEvent& e : stats_.events) {
    std::snprintf(line, sizeof line, "t=%.3fs after frame %llu: %s%s\n", e.t_ns * 1e-9,
                  static_cast<unsigned long long>(e.last_sequence), eventName(e.kind),
                  e.kind == SourceEventKind::kGap
                      ? (" (" + std::to_string(e.frames) + ")").c_str()
                      : "");
    text += line;
  }
  if (stats_.events_dropped > 0)
    text += "(" + std::to_string(stats_.events_dropped) + " later events not kept)\n";
  return text;
}

}  // namespace plumb

#pragma once
// ResilientSource: supervises a live FrameSource. When the source fails (kError: unplugged,
// driver error) or stalls for longer than a timeout, it records the event, reopens the source
// with exponential backoff, and carries on; frames lost meanwhile are counted from the gaps in
// RgbdImage::sequence. The pipeline downstream keeps its map and simply sees a sequence gap.
//
// next() blocks while reconnecting (sleeping through the injected clock), which is what a capture
// thread wants; it returns kError only when max_reopen_attempts is exhausted.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "drivers/common/frame_source.h"
#include "drivers/fault/source_clock.h"
#include "platform/fixed_vector.h"

namespace plumb {

struct ResilientSourceOptions {
  int64_t initial_backoff_ns = 50'000'000;  // 50 ms: USB re-enumeration takes about this long
  double backoff_multiplier = 2.0;
  int64_t max_backoff_ns = 2'000'000'000;   // 2 s: retry often enough to catch a replug quickly
  int max_reopen_attempts = 30;             // per failure; 0 = retry forever
  // No frame for this long (only kNoFrame results) counts as a failure and triggers a reopen.
  // 0 disables it. 3 s is ~100 frames at 30 Hz: far beyond any healthy USB hiccup.
  int64_t stall_timeout_ns = 3'000'000'000;
  // > 0: backoff sleeps are cut into slices this long, and end early when wakeReconnect() was
  // called (a USB arrival) or a stop was requested; and after deviceLeft() (the camera left the
  // bus) reopen attempts wait, in such slices, for its arrival. 0: whole sleeps and no waiting
  // for arrivals (what the tests' virtual clock schedule checks); sources opened from a spec use
  // 20 ms.
  int64_t wake_slice_ns = 0;
  // After a departure, how long reopen attempts wait for the arrival before they go on with the
  // backoff schedule anyway (an arrival event may be missed: udev restarted, a hub reset). The
  // wait uses no attempt of the budget. 30 s: a replug by hand takes a few seconds.
  int64_t absent_wait_ns = 30'000'000'000;
};

enum class SourceEventKind { kError, kStallTimeout, kReopenFailed, kReconnected, kGaveUp, kGap, kWoken, kDeparted };

struct SourceEvent {
  int64_t t_ns = 0;           // clock time of the event
  SourceEventKind kind = SourceEventKind::kError;
  uint64_t frames = 0;        // kGap: frames missing; kReconnected: attempts it took
  uint64_t last_sequence = 0; // the last frame delivered before the event
};

struct ResilienceStats {
  uint64_t frames_delivered = 0;
  uint64_t frames_missing = 0;    // sum of sequence gaps
  uint64_t gaps = 0;              // number of gaps
  uint64_t no_frame_results = 0;  // kNoFrame passed through (timeouts)
  uint64_t errors = 0;            // kError results seen from the source
  uint64_t stall_timeouts = 0;
  uint64_t reopen_attempts = 0;
  uint64_t reopen_failures = 0;
  uint64_t reconnects = 0;
  uint64_t hotplug_wakeups = 0;      // waits and backoffs ended by wakeReconnect() (USB arrival)
  uint64_t usb_departures = 0;       // outages in which deviceLeft() was heard (once per outage)
  uint64_t outages = 0;              // failures that started a reconnection
  int64_t time_disconnected_ns = 0;  // summed from failure to successful reopen
  int64_t longest_outage_ns = 0;
  int64_t arrival_to_frame_ns = -1;  // the last woken reconnection: arrival -> first frame (-1: none)
  // The first kMaxEvents events (bounded: a flapping sensor must not grow memory).
  static constexpr std::size_t kMaxEvents = 64;
  FixedVector<SourceEvent, kMaxEvents> events;
  uint64_t events_dropped = 0;
  std::string last_error;
};

class ResilientSource : public FrameSource {
 public:
  ResilientSource(std::unique_ptr<FrameSource> inner, const ResilientSourceOptions& options,
                  SourceClock& clock = steadyClock());

  SourceResult next(RgbdImage& out) override;
  const PinholeCamera& camera() const override { return inner_->camera(); }
  std::string describe() const override { return "resilient(" + inner_->describe() + ")"; }
  const Status& lastError() const override { return error_; }
  Status reopen() override { return inner_->reopen(); }
  bool isLive() const override { return inner_->isLive(); }
  // "source: errors N, stall timeouts N, reconnects N (T s disconnected, N failed reopens), frames
  // missing N in N gaps" and, after "; ", the supervised source's own report; then the events
  // (describeEvents), each line indented by two spaces.
  std::string healthReport() const override;
  // While reconnecting, the flag is checked before every attempt and after every backoff sleep:
  // once set, next() returns kNoFrame (at most one backoff, 2 s, later).
  void setStopFlag(const std::atomic<bool>* stop) override {
    stop_ = stop;
    inner_->setStopFlag(stop);
  }
  // Thread-safe (the hot-plug listener's thread), with wake_slice_ns > 0. wakeReconnect: the
  // camera arrived: the next reopen attempt of a reconnection in progress (or starting) happens
  // now instead of after its backoff or its wait for the arrival. deviceLeft: the camera left:
  // the next next() call reports the disconnect (event "usb camera left") and reconnects, and
  // reopen attempts wait for the arrival (at most absent_wait_ns).
  void wakeReconnect() override;
  void deviceLeft() override;
  bool supervision(SourceSupervision* out) const override;

  const ResilienceStats& stats() const { return stats_; }
  // One line per event ("t=1.250s error: ..."), for run reports.
  std::string describeEvents() const;

 private:
  // Reopens with backoff; true when the source is back.
  bool recover();
  // The backoff before the next reopen attempt; ends early on a wake-up or a stop request.
  void sleepBackoff(int64_t backoff_ns);
  // While the camera is off the bus: waits for its arrival (or a stop, or absent_wait_ns).
  void waitForArrival(int64_t failed_at_ns);
  // An arrival ended a wait: counted, and the first frame after the reconnection is timed.
  void noteWoken();
  void record(SourceEventKind kind, uint64_t frames = 0);

  std::unique_ptr<FrameSource> inner_;
  ResilientSourceOptions options_;
  SourceClock& clock_;
  ResilienceStats stats_;
  Status error_;
  const std::atomic<bool>* stop_ = nullptr;
  std::atomic<bool> wake_{false};      // an arrival not yet acted on
  std::atomic<bool> absent_{false};    // the camera is off the bus (between departure and arrival)
  std::atomic<bool> departed_{false};  // a departure not yet reported by next() or recover()
  std::atomic<int64_t> arrival_ns_{0};  // clock time of the last arrival
  bool woken_ = false;                  // this reconnection was woken by an arrival
  bool time_first_frame_ = false;       // the next frame ends arrival_to_frame_ns
  bool stopRequested() const { return stop_ != nullptr && stop_->load(std::memory_order_relaxed); }
  bool have_last_sequence_ = false;
  uint64_t last_sequence_ = 0;
  int64_t last_frame_ns_ = 0;
};

}  // namespace plumb

#pragma once
// FrameSource: the one interface every producer of RGB-D frames implements — dataset replay,
// synthetic scenes, our recordings, OpenNI2, V4L2. The pipeline's capture stage only sees this.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>

#include "sensor/camera.h"
#include "sensor/rgbd_image.h"
#include "platform/status.h"

namespace plumb {

enum class SourceResult {
  kFrame,        // `out` holds a new frame
  kEndOfStream,  // a finite source is exhausted (clean end)
  kNoFrame,      // a live source had nothing this time (timeout); try again
  kError,        // see lastError(); a live source may recover after reopen()
};

// Damage a source found and skipped (a recording's corrupt chunks, a cut tail). Counted and
// reported by every command that reads a source: nothing is skipped silently.
struct SourceDamage {
  uint64_t regions_skipped = 0;      // damaged regions (each may have held a frame)
  uint64_t bytes_skipped = 0;
  uint64_t truncated_tail_bytes = 0;  // an incomplete last write (power cut)
  bool closed_properly = true;       // the writer finished the file
  std::string last;                  // the last damage, e.g. "chunk at byte 1234: CRC mismatch"
  bool any() const { return regions_skipped > 0 || truncated_tail_bytes > 0 || !closed_properly; }
};

// What supervision of a live source counted (drivers/fault/resilient_source.h), for statistics.
struct SourceSupervision {
  uint64_t errors = 0, stall_timeouts = 0, reconnects = 0, reopen_failures = 0;
  uint64_t outages = 0;                // failures (errors, stalls, departures) that needed a reopen
  uint64_t usb_departures = 0;         // the camera left the bus (libusb), counted once per outage
  uint64_t usb_arrivals = 0;           // arrivals that ended a wait or a backoff (hot-plug wake-ups)
  uint64_t frames_missing = 0, gaps = 0;
  int64_t disconnected_ns = 0;         // summed over the outages
  int64_t longest_outage_ns = 0;       // failure -> successful reopen, the longest one
  // The last reconnection an arrival woke: arrival event -> first frame delivered after it
  // (-1: none). Tracking that frame takes the run's per-frame time on top.
  int64_t arrival_to_frame_ns = -1;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // Fills `out` (reusing its buffers). Never throws.
  virtual SourceResult next(RgbdImage& out) = 0;
  virtual const PinholeCamera& camera() const = 0;
  // Human-readable name, e.g. "tum:/data/fr1_rpy" or "openni2:first".
  virtual std::string describe() const = 0;
  virtual const Status& lastError() const = 0;
  // For live sources: try to reopen after an error (returns the outcome). Replays: no-op error.
  virtual Status reopen() { return Status::Error(describe() + ": cannot be reopened"); }
  virtual bool isLive() const { return false; }
  // Frames a finite source will deliver, when known in advance (a dataset folder, a synthetic
  // scene); 0 when unknown (live sensors, recordings). Lets callers reserve memory once.
  virtual std::size_t frameCount() const { return 0; }
  // What the source skipped so far (see SourceDamage); none for sources that cannot be damaged.
  virtual SourceDamage damage() const { return SourceDamage{}; }
  // Live sources: what supervision and capture counted (errors, reconnects, time disconnected,
  // frames missing, unpaired colour/depth, driver-flagged buffers), for run reports: a summary
  // line, then one line per recorded event. Empty when there is nothing to report (replays).
  virtual std::string healthReport() const { return ""; }
  // A flag the caller sets to end the run (SIGINT): a live source that blocks (reconnecting with
  // backoff) checks it and returns kNoFrame soon after. nullptr = none. Wrappers forward it.
  virtual void setStopFlag(const std::atomic<bool>* stop) { (void)stop; }
  // Hot-plug hints, from any thread (the libusb listener, drivers/usb/usb_arrival_waker.h).
  // wakeReconnect: the camera arrived: a live source waiting to reconnect tries now rather than
  // after its backoff. deviceLeft: the camera left the bus: a supervised source reports the
  // disconnect at once (without waiting for errors or its stall timeout) and reopens only once
  // it arrives again. Wrappers forward both.
  virtual void wakeReconnect() {}
  virtual void deviceLeft() {}
  // Supervised live sources: the outages for `plumb run --stats` (false: not supervised).
  virtual bool supervision(SourceSupervision* out) const {
    (void)out;
    return false;
  }
};

}  // namespace plumb

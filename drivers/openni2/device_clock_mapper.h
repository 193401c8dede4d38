#pragma once
// DeviceClockMapper: maps a sensor's own frame timestamps onto the host monotonic clock.
//
// Each frame gives a sample offset = host_receive_time - device_time: the clocks' difference plus
// that frame's transfer latency. The smallest sample of the last kWindow frames (~2 s at 30 Hz)
// is the estimate: the least-delayed frame bounds the true offset, so USB latency jitter does not
// come through, and a sliding window follows the slow drift of the device's crystal
// (10-100 ppm: < 0.2 ms over the window). A jump beyond reset_threshold_ns (device clock
// restarted, e.g. after a reconnect) clears the window and re-anchors the mapping.
// Header-only and free of OpenNI, so it is tested without the library.
#include <array>
#include <cstdint>
#include <cstdlib>

namespace plumb {

class DeviceClockMapper {
 public:
  static constexpr int kWindow = 64;

  explicit DeviceClockMapper(int64_t reset_threshold_ns = 1'000'000'000)
      : reset_threshold_ns_(reset_threshold_ns) {}

  // Host monotonic time at which the frame stamped `device_ns` was captured, given that it was
  // received at `host_receive_ns`. Never later than the receive time.
  int64_t toHostNs(int64_t device_ns, int64_t host_receive_ns) {
    const int64_t sample = host_receive_ns - device_ns;
    if (count_ > 0 && std::llabs(sample - offset_ns_) > reset_threshold_ns_) {
      ++resets_;
      count_ = 0;
    }
    window_[next_] = sample;
    next_ = (next_ + 1) % kWindow;
    if (count_ < kWindow) ++count_;
    offset_ns_ = sample;
    for (int i = 0; i < count_; ++i) {
      const int64_t s = window_[(next_ + kWindow - 1 - i) % kWindow];
      if (s < offset_ns_) offset_ns_ = s;
    }
    const int64_t host_ns = device_ns + offset_ns_;
    return host_ns < host_receive_ns ? host_ns : host_receive_ns;
  }

  int64_t offsetNs() const { return offset_ns_; }
  uint64_t resets() const { return resets_; }

 private:
  int64_t reset_threshold_ns_;
  std::array<int64_t, kWindow> window_{};
  int count_ = 0;
  int next_ = 0;
  int64_t offset_ns_ = 0;
  uint64_t resets_ = 0;
};

}  // namespace plumb

#pragma once
// UsbArrivalWaker: tells a live source that its camera may be back as soon as libusb reports an
// RGB-D camera (VID:PID table) arriving, so a reconnection tries at once instead of waiting out
// its backoff (up to 2 s): "reconnect from the hot-plug event". It listens on a thread of its own
// (libusb events are delivered by polling), started by start() and joined by the destructor.
// pollOnce() is that thread's loop body, for tests without a thread.
#include <atomic>
#include <functional>
#include <memory>
#include <thread>

#include "drivers/usb/camera_monitor.h"
#include "drivers/usb/usb_backend.h"

namespace plumb {

class UsbArrivalWaker {
 public:
  // `on_arrival` is called on the listening thread. Fails (nothing started) when the backend has
  // no hot-plug support.
  static Status create(std::unique_ptr<UsbBackend> backend, std::function<void()> on_arrival,
                       std::unique_ptr<UsbArrivalWaker>* out);
  ~UsbArrivalWaker();
  UsbArrivalWaker(const UsbArrivalWaker&) = delete;
  UsbArrivalWaker& operator=(const UsbArrivalWaker&) = delete;

  void startThread();                 // polls every 100 ms until destruction
  Status pollOnce(int timeout_ms);    // delivers pending events (calls on_arrival per camera)
  uint64_t arrivals() const { return arrivals_.load(std::memory_order_relaxed); }

 private:
  UsbArrivalWaker(std::unique_ptr<UsbBackend> backend, std::function<void()> on_arrival);

  std::unique_ptr<UsbBackend> backend_;
  CameraMonitor monitor_;
  std::function<void()> on_arrival_;
  std::atomic<uint64_t> arrivals_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace plumb

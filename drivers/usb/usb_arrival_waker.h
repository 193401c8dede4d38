#pragma once
// UsbArrivalWaker: the libusb side of "reconnect from the hot-plug event". It listens for USB
// arrivals and departures on a thread of its own (libusb delivers hot-plug events by polling;
// startThread() starts it, the destructor joins it) and tells a live source about its camera:
//   - with a configured VID:PID (spec suffix `@usb=8086:0b07`): that device arriving calls
//     `arrived` (a reconnection tries at once), that device leaving calls `left` (the run reports
//     the disconnect at once and waits for the arrival instead of reopening a camera that is gone);
//   - without one: any RGB-D camera of the VID:PID table (usb_camera_table.h) arriving calls
//     `arrived`; departures are ignored (nothing says which camera is the run's).
// pollOnce() is the thread's loop body, for tests without a thread.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "drivers/usb/usb_backend.h"

namespace plumb {

// The USB identity of the run's camera; 0:0 = not configured (any camera of the table).
struct UsbCameraId {
  uint16_t vendor_id = 0;
  uint16_t product_id = 0;
  bool configured() const { return vendor_id != 0 || product_id != 0; }
};
// "8086:0b07" (hex, 1-4 digits each) -> id; false for anything else (incl. 0000:0000).
bool parseUsbCameraId(const std::string& text, UsbCameraId* id);

struct UsbCameraEvents {
  std::function<void()> arrived;  // called on the listening thread
  std::function<void()> left;
};

class UsbArrivalWaker : private UsbHotplugHandler {
 public:
  // Fails (nothing started) when the backend has no hot-plug support.
  static Status create(std::unique_ptr<UsbBackend> backend, const UsbCameraId& camera, UsbCameraEvents events,
                       std::unique_ptr<UsbArrivalWaker>* out);
  ~UsbArrivalWaker() override;
  UsbArrivalWaker(const UsbArrivalWaker&) = delete;
  UsbArrivalWaker& operator=(const UsbArrivalWaker&) = delete;

  void startThread();               // polls every 100 ms until destruction
  Status pollOnce(int timeout_ms);  // delivers pending events
  uint64_t arrivals() const { return arrivals_.load(std::memory_order_relaxed); }
  uint64_t departures() const { return departures_.load(std::memory_order_relaxed); }
  // "usb 8086:0b07 arrived 1, left 1" or "usb: RGB-D cameras arrived 1" (no VID:PID configured).
  std::string describe() const;

 private:
  UsbArrivalWaker(std::unique_ptr<UsbBackend> backend, const UsbCameraId& camera, UsbCameraEvents events);
  bool isTheCamera(const UsbDeviceId& device) const;
  void onArrived(const UsbDeviceId& device) override;
  void onLeft(const UsbDeviceId& device) override;

  std::unique_ptr<UsbBackend> backend_;
  UsbCameraId camera_;
  UsbCameraEvents events_;
  std::atomic<uint64_t> arrivals_{0}, departures_{0};
  std::atomic<bool> stop_{false};
  bool hotplug_started_ = false;
  std::thread thread_;
};

}  // namespace plumb

#include "drivers/usb/usb_arrival_waker.h"

namespace plumb {

UsbArrivalWaker::UsbArrivalWaker(std::unique_ptr<UsbBackend> backend, std::function<void()> on_arrival)
    : backend_(std::move(backend)), monitor_(*backend_), on_arrival_(std::move(on_arrival)) {}

Status UsbArrivalWaker::create(std::unique_ptr<UsbBackend> backend, std::function<void()> on_arrival,
                               std::unique_ptr<UsbArrivalWaker>* out) {
  std::unique_ptr<UsbArrivalWaker> waker(new UsbArrivalWaker(std::move(backend), std::move(on_arrival)));
  UsbArrivalWaker* self = waker.get();
  PLUMB_RETURN_IF_ERROR(waker->monitor_.start([self](const CameraChange& change) {
    if (!change.arrived) return;
    self->arrivals_.fetch_add(1, std::memory_order_relaxed);
    self->on_arrival_();
  }));
  *out = std::move(waker);
  return Status::Ok();
}

UsbArrivalWaker::~UsbArrivalWaker() {
  stop_.store(true, std::memory_order_relaxed);
  if (thread_.joinable()) thread_.join();
  monitor_.stop();
}

void UsbArrivalWaker::startThread() {
  if (thread_.joinable()) return;
  thread_ = std::thread([this] {
    while (!stop_.load(std::memory_order_relaxed)) {
      if (!pollOnce(100).ok()) return;  // libusb failed: no more hints, the backoff still works
    }
  });
}

Status UsbArrivalWaker::pollOnce(int timeout_ms) { return monitor_.pollEvents(timeout_ms); }

}  // namespace plumb

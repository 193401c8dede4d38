#include "drivers/usb/usb_arrival_waker.h"

#include <cstdio>
#include <cstdlib>

#include "drivers/usb/usb_camera_table.h"

namespace plumb {
namespace {

bool parseHex16(const std::string& text, uint16_t* value) {
  if (text.empty() || text.size() > 4) return false;
  char* end = nullptr;
  const unsigned long v = std::strtoul(text.c_str(), &end, 16);
  if (*end != '\0' || text[0] == '-' || text[0] == '+') return false;
  *value = static_cast<uint16_t>(v);
  return true;
}

}  // namespace

bool parseUsbCameraId(const std::string& text, UsbCameraId* id) {
  const std::size_t colon = text.find(':');
  if (colon == std::string::npos) return false;
  UsbCameraId parsed;
  if (!parseHex16(text.substr(0, colon), &parsed.vendor_id) || !parseHex16(text.substr(colon + 1), &parsed.product_id))
    return false;
  if (!parsed.configured()) return false;
  *id = parsed;
  return true;
}

UsbArrivalWaker::UsbArrivalWaker(std::unique_ptr<UsbBackend> backend, const UsbCameraId& camera,
                                 UsbCameraEvents events)
    : backend_(std::move(backend)), camera_(camera), events_(std::move(events)) {}

Status UsbArrivalWaker::create(std::unique_ptr<UsbBackend> backend, const UsbCameraId& camera,
                               UsbCameraEvents events, std::unique_ptr<UsbArrivalWaker>* out) {
  if (!backend->supportsHotplug()) return Status::Error("libusb: hot-plug is not supported here");
  std::unique_ptr<UsbArrivalWaker> waker(new UsbArrivalWaker(std::move(backend), camera, std::move(events)));
  PLUMB_RETURN_IF_ERROR(waker->backend_->startHotplug(waker.get()));
  waker->hotplug_started_ = true;
  *out = std::move(waker);
  return Status::Ok();
}

UsbArrivalWaker::~UsbArrivalWaker() {
  stop_.store(true, std::memory_order_relaxed);
  if (thread_.joinable()) thread_.join();
  if (hotplug_started_) backend_->stopHotplug();
}

void UsbArrivalWaker::startThread() {
  if (thread_.joinable()) return;
  thread_ = std::thread([this] {
    while (!stop_.load(std::memory_order_relaxed)) {
      if (!pollOnce(100).ok()) return;  // libusb failed: no more hints, the backoff still works
    }
  });
}

Status UsbArrivalWaker::pollOnce(int timeout_ms) { return backend_->pollEvents(timeout_ms); }

bool UsbArrivalWaker::isTheCamera(const UsbDeviceId& device) const {
  if (camera_.configured()) return device.vendor_id == camera_.vendor_id && device.product_id == camera_.product_id;
  return lookupUsbCamera(device.vendor_id, device.product_id) != nullptr;
}

void UsbArrivalWaker::onArrived(const UsbDeviceId& device) {
  if (!isTheCamera(device)) return;
  arrivals_.fetch_add(1, std::memory_order_relaxed);
  if (events_.arrived) events_.arrived();
}

void UsbArrivalWaker::onLeft(const UsbDeviceId& device) {
  if (!camera_.configured() || !isTheCamera(device)) return;
  departures_.fetch_add(1, std::memory_order_relaxed);
  if (events_.left) events_.left();
}

std::string UsbArrivalWaker::describe() const {
  char text[96];
  if (camera_.configured()) {
    std::snprintf(text, sizeof text, "usb %04x:%04x arrived %llu, left %llu", camera_.vendor_id, camera_.product_id,
                  static_cast<unsigned long long>(arrivals()), static_cast<unsigned long long>(departures()));
  } else {
    std::snprintf(text, sizeof text, "usb: RGB-D cameras arrived %llu", static_cast<unsigned long long>(arrivals()));
  }
  return text;
}

}  // namespace plumb

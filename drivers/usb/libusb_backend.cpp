#include "drivers/usb/libusb_backend.h"

#include <libusb.h>

namespace plumb {
namespace {

std::string portPath(libusb_device* device) {
  uint8_t ports[8];
  const int n = libusb_get_port_numbers(device, ports, sizeof ports);
  std::string path = std::to_string(libusb_get_bus_number(device));
  for (int i = 0; i < n; ++i) path += (i == 0 ? "-" : ".") + std::to_string(ports[i]);
  return path;
}

bool describeDevice(libusb_device* device, UsbDeviceId* id) {
  libusb_device_descriptor descriptor{};
  if (libusb_get_device_descriptor(device, &descriptor) != 0) return false;
  id->vendor_id = descriptor.idVendor;
  id->product_id = descriptor.idProduct;
  id->bus = libusb_get_bus_number(device);
  id->port_path = portPath(device);
  return true;
}

class LibusbBackend : public UsbBackend {
 public:
  explicit LibusbBackend(libusb_context* context) : context_(context) {}
  ~LibusbBackend() override {
    stopHotplug();
    libusb_exit(context_);
  }

  Status listDevices(std::vector<UsbDeviceId>* devices) override {
    libusb_device** list = nullptr;
    const ssize_t n = libusb_get_device_list(context_, &list);
    if (n < 0)
      return Status::Error(std::string("libusb_get_device_list failed: ") +
                           libusb_error_name(static_cast<int>(n)));
    devices->clear();
    for (ssize_t i = 0; i < n; ++i) {
      UsbDeviceId id;
      if (describeDevice(list[i], &id)) devices->push_back(id);
    }
    libusb_free_device_list(list, 1);
    return Status::Ok();
  }

  bool supportsHotplug() const override {
    return libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG) != 0;
  }

  Status startHotplug(UsbHotplugHandler* handler) override {
    if (!supportsHotplug()) return Status::Error("libusb: hot-plug not supported on this platform");
    stopHotplug();
    handler_ = handler;
    const int r = libusb_hotplug_register_callback(
        context_,
        static_cast<libusb_hotplug_event>(LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED |
                                          LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT),
        static_cast<libusb_hotplug_flag>(0), LIBUSB_HOTPLUG_MATCH_ANY, LIBUSB_HOTPLUG_MATCH_ANY,
        LIBUSB_HOTPLUG_MATCH_ANY, &LibusbBackend::onEvent, this, &callback_);
    if (r != LIBUSB_SUCCESS) {
      handler_ = nullptr;
      return Status::Error(std::string("libusb_hotplug_register_callback failed: ") +
                           libusb_error_name(r));
    }
    registered_ = true;
    return Status::Ok();
  }

  void stopHotplug() override {
    if (registered_) libusb_hotplug_deregister_callback(context_, callback_);
    registered_ = false;
    handler_ = nullptr;
  }

  Status pollEvents(int timeout_ms) override {
    timeval tv{timeout_ms / 1000, (timeout_ms % 1000) * 1000};
    const int r = libusb_handle_events_timeout_completed(context_, &tv, nullptr);
    if (r != LIBUSB_SUCCESS && r != LIBUSB_ERROR_INTERRUPTED)
      return Status::Error(std::string("libusb_handle_events failed: ") + libusb_error_name(r));
    return Status::Ok();
  }

 private:
  static int LIBUSB_CALL onEvent(libusb_context*, libusb_device* device,
                                 libusb_hotplug_event event, void* user) {
    auto* self = static_cast<LibusbBackend*>(user);
    UsbDeviceId id;
    if (self->handler_ && describeDevice(device, &id)) {
      if (event == LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED) self->handler_->onArrived(id);
      if (event == LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT) self->handler_->onLeft(id);
    }
    return 0;  // stay registered
  }

  libusb_context* context_;
  UsbHotplugHandler* handler_ = nullptr;
  libusb_hotplug_callback_handle callback_{};
  bool registered_ = false;
};

}  // namespace

Status openLibusbBackend(std::unique_ptr<UsbBackend>* out) {
  libusb_context* context = nullptr;
  const int r = libusb_init(&context);
  if (r != LIBUSB_SUCCESS)
    return Status::Error(std::string("libusb_init failed: ") + libusb_error_name(r) +
                         " (no USB access on this machine?)");
  *out = std::make_unique<LibusbBackend>(context);
  return Status::Ok();
}

}  // namespace plumb

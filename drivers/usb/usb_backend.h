#pragma once
// UsbBackend: the seam between libusb and plumb's camera discovery logic. The real backend
// (libusb_backend.h) enumerates the bus and delivers hot-plug events; tests inject devices and
// events through a fake, so the discovery logic is tested without hardware.
#include <cstdint>
#include <string>
#include <vector>

#include "platform/status.h"

namespace plumb {

struct UsbDeviceId {
  uint16_t vendor_id = 0;
  uint16_t product_id = 0;
  uint8_t bus = 0;
  std::string port_path;  // "bus-port.port..." as in sysfs, e.g. "1-4.2"
  bool operator==(const UsbDeviceId& o) const {
    return vendor_id == o.vendor_id && product_id == o.product_id && bus == o.bus &&
           port_path == o.port_path;
  }
};

class UsbHotplugHandler {
 public:
  virtual ~UsbHotplugHandler() = default;
  virtual void onArrived(const UsbDeviceId& device) = 0;
  virtual void onLeft(const UsbDeviceId& device) = 0;
};

class UsbBackend {
 public:
  virtual ~UsbBackend() = default;
  virtual Status listDevices(std::vector<UsbDeviceId>* devices) = 0;
  virtual bool supportsHotplug() const = 0;
  // Registers `handler` for arrivals and departures (not called for devices already present).
  virtual Status startHotplug(UsbHotplugHandler* handler) = 0;
  virtual void stopHotplug() = 0;
  // Delivers pending hot-plug events to the handler, waiting up to timeout_ms for one.
  virtual Status pollEvents(int timeout_ms) = 0;
};

}  // namespace plumb

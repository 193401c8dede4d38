#pragma once
// LibusbBackend: UsbBackend over libusb-1.0 (own context, so it never disturbs other libusb
// users in the process). Hot-plug uses libusb_hotplug_register_callback when
// libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG) says the platform supports it.
#include <memory>

#include "drivers/usb/usb_backend.h"

namespace plumb {

// Fails with a clear message when libusb cannot be initialised (e.g. no USB access at all).
Status openLibusbBackend(std::unique_ptr<UsbBackend>* out);

}  // namespace plumb

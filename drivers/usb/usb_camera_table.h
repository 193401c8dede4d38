#pragma once
// Known RGB-D cameras by USB vendor:product id, and which plumb source can open each.
// The ids were collected from vendors' public driver sources and udev rules; see
// docs/DRIVERS.md for the list and its caveats (a PID can be shared by several product names).
#include <cstddef>
#include <cstdint>

namespace plumb {

enum class CameraAccess {
  kOpenNI2,       // plumb's openni2 source (needs the vendor's OpenNI2 driver for the device)
  kV4l2,          // plumb's v4l2 source: the kernel's uvcvideo exposes colour and Z16 depth
  kUnsupported,   // recognised, but no plumb source can open it (e.g. needs libfreenect2)
};

struct UsbCameraModel {
  uint16_t vendor_id;
  uint16_t product_id_first, product_id_last;  // inclusive range (one id: first == last)
  const char* name;
  CameraAccess access;
  const char* note;  // what is needed to open it, shown by `plumb devices`
};

// The entry matching (vid, pid), or nullptr for a device that is not a known RGB-D camera.
const UsbCameraModel* lookupUsbCamera(uint16_t vendor_id, uint16_t product_id);

// "openni2", "v4l2", "none".
const char* cameraAccessName(CameraAccess access);

// The whole table, for documentation and tests.
const UsbCameraModel* usbCameraTable(std::size_t* count);

}  // namespace plumb

#pragma once
// OpenNI2 source (Debian libopenni2): live PrimeSense-family sensors, or an .oni recording.
//
//   uri ""           the first device OpenNI2 finds
//   uri "<uri>"      a device URI as listOpenNI2Devices() reports it
//   uri "<file>.oni" an OpenNI recording, played by OpenNI2's OniFile driver
//
// Streams: depth (1 mm units, depth_factor 1000) and RGB colour at width x height @ fps,
// depth registered to colour (IMAGE_REGISTRATION_DEPTH_TO_COLOR when the device supports it),
// depth/colour frame sync on, mirroring off. Intrinsics: from the device's field of view when it
// reports one, else from `fallback_camera` (a camera file or preset); neither is an error.
// Timestamps: the device clock mapped to the host monotonic clock (device_clock_mapper.h).
//
// Built without OpenNI2 (no pkg-config libopenni2), every call returns "built without OpenNI2".
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "drivers/common/frame_source.h"

namespace plumb {

struct OpenNI2SourceOptions {
  std::string uri;  // "" = first device; or a device URI; or an .oni path
  int width = 640, height = 480, fps = 30;
  bool register_depth_to_colour = true;
  bool sync_depth_colour = true;
  bool mirror = false;
  int read_timeout_ms = 200;  // kNoFrame after this long (6 frames at 30 Hz)
  // Prefer a given camera over the device's nominal field of view (a calibration is better).
  bool prefer_fallback_camera = false;
};

struct OpenNI2DeviceInfo {
  std::string uri, vendor, name;
  uint16_t usb_vendor_id = 0, usb_product_id = 0;
};

// Initialises OpenNI2 once per process (later calls return the first outcome).
Status initializeOpenNI2();
// Lists connected devices; an empty list is success (print "no OpenNI2 device found").
Status listOpenNI2Devices(std::vector<OpenNI2DeviceInfo>* devices);
// `fallback_camera` may be null. Errors name the URI or file.
Status openOpenNI2Source(const OpenNI2SourceOptions& options, const PinholeCamera* fallback_camera,
                         std::unique_ptr<FrameSource>* out);
// Whether this build has OpenNI2 at all.
bool openNI2Available();

#ifndef PLUMB_HAVE_OPENNI2
inline Status initializeOpenNI2() { return Status::Error("built without OpenNI2 (libopenni2-dev)"); }
inline Status listOpenNI2Devices(std::vector<OpenNI2DeviceInfo>*) { return initializeOpenNI2(); }
inline Status openOpenNI2Source(const OpenNI2SourceOptions&, const PinholeCamera*,
                                std::unique_ptr<FrameSource>*) {
  return initializeOpenNI2();
}
inline bool openNI2Available() { return false; }
#endif

}  // namespace plumb

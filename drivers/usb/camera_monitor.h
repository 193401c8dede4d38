#pragma once
// CameraMonitor: which RGB-D cameras are connected, kept current by hot-plug events.
// scan() lists the bus once; start() subscribes to arrivals and departures. Only devices found
// in the VID:PID table (usb_camera_table.h) count as cameras; events for other devices, repeated
// arrivals and departures of unknown devices are ignored, so listeners see each change once.
#include <functional>
#include <string>
#include <vector>

#include "drivers/usb/usb_backend.h"
#include "drivers/usb/usb_camera_table.h"

namespace plumb {

struct DetectedCamera {
  UsbDeviceId usb;
  const UsbCameraModel* model = nullptr;
};

struct CameraChange {
  bool arrived = false;  // false: the camera left
  DetectedCamera camera;
};

// "8086:0b07 Intel RealSense D435 at usb 2-3.1 -> v4l2 (uvcvideo: colour + Z16 nodes)"
std::string describeCamera(const DetectedCamera& camera);
// One line per camera, or a plain "no RGB-D camera connected" line when the list is empty.
std::string describeCameras(const std::vector<DetectedCamera>& cameras);

class CameraMonitor : private UsbHotplugHandler {
 public:
  using Listener = std::function<void(const CameraChange&)>;
  explicit CameraMonitor(UsbBackend& backend) : backend_(backend) {}
  ~CameraMonitor() override { stop(); }

  // Replaces the current list with the cameras on the bus now.
  Status scan();
  // Hot-plug: `listener` hears every camera arriving or leaving. Fails cleanly if unsupported.
  Status start(Listener listener);
  void stop();
  Status pollEvents(int timeout_ms) { return backend_.pollEvents(timeout_ms); }

  const std::vector<DetectedCamera>& cameras() const { return cameras_; }

 private:
  void onArrived(const UsbDeviceId& device) override;
  void onLeft(const UsbDeviceId& device) override;

  UsbBackend& backend_;
  std::vector<DetectedCamera> cameras_;
  Listener listener_;
  bool started_ = false;
};

}  // namespace plumb

#include "drivers/usb/camera_monitor.h"

#include <algorithm>
#include <cstdio>

namespace plumb {

std::string describeCamera(const DetectedCamera& camera) {
  char ids[16];
  std::snprintf(ids, sizeof ids, "%04x:%04x", camera.usb.vendor_id, camera.usb.product_id);
  return std::string(ids) + " " + camera.model->name + " at usb " + camera.usb.port_path +
         " -> " + cameraAccessName(camera.model->access) + " (" + camera.model->note + ")";
}

std::string describeCameras(const std::vector<DetectedCamera>& cameras) {
  if (cameras.empty()) return "no RGB-D camera connected (USB bus scanned, none in the VID:PID table)\n";
  std::string text;
  for (const DetectedCamera& c : cameras) text += describeCamera(c) + "\n";
  return text;
}

Status CameraMonitor::scan() {
  std::vector<UsbDeviceId> devices;
  PLUMB_RETURN_IF_ERROR(backend_.listDevices(&devices));
  cameras_.clear();
  for (const UsbDeviceId& d : devices) {
    if (const UsbCameraModel* model = lookupUsbCamera(d.vendor_id, d.product_id))
      cameras_.push_back(DetectedCamera{d, model});
  }
  return Status::Ok();
}

Status CameraMonitor::start(Listener listener) {
  if (!backend_.supportsHotplug())
    return Status::Error("hot-plug is not supported here; call scan() to refresh");
  listener_ = std::move(listener);
  PLUMB_RETURN_IF_ERROR(backend_.startHotplug(this));
  started_ = true;
  return Status::Ok();
}

void CameraMonitor::stop() {
  if (started_) backend_.stopHotplug();
  started_ = false;
}

void CameraMonitor::onArrived(const UsbDeviceId& device) {
  const UsbCameraModel* model = lookupUsbCamera(device.vendor_id, device.product_id);
  if (!model) return;
  const bool known = std::any_of(cameras_.begin(), cameras_.end(),
                                 [&](const DetectedCamera& c) { return c.usb == device; });
  if (known) return;
  cameras_.push_back(DetectedCamera{device, model});
  if (listener_) listener_(CameraChange{true, cameras_.back()});
}

void CameraMonitor::onLeft(const UsbDeviceId& device) {
  auto it = std::find_if(cameras_.begin(), cameras_.end(),
                         [&](const DetectedCamera& c) { return c.usb == device; });
  if (it == cameras_.end()) return;
  const DetectedCamera gone = *it;
  cameras_.erase(it);
  if (listener_) listener_(CameraChange{false, gone});
}

}  // namespace plumb

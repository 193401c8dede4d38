#include "drivers/open/sensor_source_specs.h"

#include <cstdio>
#include <cstdlib>

#include "drivers/open/open_source.h"
#include "drivers/common/forwarding_source.h"
#include "drivers/dataset/camera_presets.h"
#include "drivers/fault/resilient_source.h"
#include "drivers/openni2/openni2_source.h"
#include "drivers/recording/paced_source.h"
#include "drivers/recording/recording_source.h"
#include "drivers/v4l2/v4l2_source.h"
#ifdef PLUMB_HAVE_LIBUSB
#include "drivers/usb/libusb_backend.h"
#include "drivers/usb/usb_arrival_waker.h"
#endif

namespace plumb {
namespace {

bool startsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }
bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// The live camera's USB identity (spec suffix `@usb=VVVV:PPPP`): "" when not given.
struct LiveOptions {
  std::string usb_id;
};

#ifdef PLUMB_HAVE_LIBUSB
// A supervised live source with a libusb hot-plug listener (UsbArrivalWaker): the camera arriving
// wakes a reconnection in progress; with a configured VID:PID, its departure is reported as a
// disconnect at once. Everything else is the supervised source's.
class HotplugWakingSource : public ForwardingSource {
 public:
  HotplugWakingSource(std::unique_ptr<FrameSource> supervised, std::unique_ptr<UsbArrivalWaker> waker)
      : ForwardingSource(std::move(supervised)), waker_(std::move(waker)) {}
  ~HotplugWakingSource() override { waker_.reset(); }  // the listener goes before the source it wakes
  std::string healthReport() const override {
    const std::string report = inner_->healthReport();
    const std::size_t end_of_summary = report.find('\n');
    return report.substr(0, end_of_summary) + "; " + waker_->describe() +
           (end_of_summary == std::string::npos ? "" : report.substr(end_of_summary));
  }

 private:
  std::unique_ptr<UsbArrivalWaker> waker_;
};
#endif

// Live sources are supervised (reopened with backoff); where libusb reports hot-plug events, the
// camera arriving makes the next reopen attempt happen at once (and, with `@usb=`, its departure
// is a disconnect). Without hot-plug events (no udev, no USB access): the backoff schedule alone.
Status supervised(std::unique_ptr<FrameSource> live, const LiveOptions& live_options,
                  std::unique_ptr<FrameSource>* out) {
  ResilientSourceOptions options;
  options.wake_slice_ns = 20'000'000;
  auto resilient = std::make_unique<ResilientSource>(std::move(live), options);
#ifdef PLUMB_HAVE_LIBUSB
  UsbCameraId camera;
  if (!live_options.usb_id.empty()) parseUsbCameraId(live_options.usb_id, &camera);  // checked on entry
  std::unique_ptr<UsbBackend> backend;
  std::unique_ptr<UsbArrivalWaker> waker;
  ResilientSource* target = resilient.get();
  UsbCameraEvents events{[target] { target->wakeReconnect(); }, [target] { target->deviceLeft(); }};
  Status st = openLibusbBackend(&backend);
  if (st.ok()) st = UsbArrivalWaker::create(std::move(backend), camera, std::move(events), &waker);
  if (st.ok()) {
    waker->startThread();
    *out = std::make_unique<HotplugWakingSource>(std::move(resilient), std::move(waker));
    return Status::Ok();
  }
  if (camera.configured())  // asked for, not available: say so rather than pretend
    std::fprintf(stderr, "plumb: @usb=%s: no hot-plug events (%s); reconnecting on the backoff schedule\n",
                 live_options.usb_id.c_str(), st.message().c_str());
#else
  (void)live_options;
#endif
  *out = std::move(resilient);
  return Status::Ok();
}

// Splits `SPEC@usb=VVVV:PPPP` into SPEC and the id, checked before any device is opened.
Status withoutUsbSuffix(const std::string& spec, std::string* device, LiveOptions* options) {
  const std::size_t at = spec.rfind("@usb=");
  *device = spec.substr(0, at);
  if (at == std::string::npos) return Status::Ok();
  options->usb_id = spec.substr(at + 5);
#ifdef PLUMB_HAVE_LIBUSB
  UsbCameraId id;
  if (!parseUsbCameraId(options->usb_id, &id))
    return Status::Error(spec + ": expected @usb=VID:PID in hex, e.g. @usb=8086:0b07");
  return Status::Ok();
#else
  return Status::Error(spec + ": @usb= needs libusb, and this plumb was built without it (libusb-1.0-0-dev)");
#endif
}

Status openRecording(const std::string& path, const std::string& camera_spec,
                     std::unique_ptr<FrameSource>* out) {
  std::unique_ptr<RecordingSource> source;
  PLUMB_RETURN_IF_ERROR(RecordingSource::open(path, &source));
  if (!camera_spec.empty()) {
    PinholeCamera camera;
    PLUMB_RETURN_IF_ERROR(cameraFromSpec(camera_spec, &camera));
    PLUMB_RETURN_IF_ERROR(source->overrideCamera(camera));
  }
  *out = std::move(source);
  return Status::Ok();
}

Status openOpenNI2(const std::string& uri, const std::string& camera_spec, const LiveOptions& live,
                   std::unique_ptr<FrameSource>* out) {
  PinholeCamera fallback;
  if (!camera_spec.empty()) PLUMB_RETURN_IF_ERROR(cameraFromSpec(camera_spec, &fallback));
  OpenNI2SourceOptions options;
  options.uri = uri == "first" ? "" : uri;
  std::unique_ptr<FrameSource> source;
  PLUMB_RETURN_IF_ERROR(
      openOpenNI2Source(options, camera_spec.empty() ? nullptr : &fallback, &source));
  if (!source->isLive()) {
    if (!live.usb_id.empty()) return Status::Error(uri + ": @usb= is for live cameras, not recordings");
    *out = std::move(source);
    return Status::Ok();
  }
  return supervised(std::move(source), live, out);
}

Status openV4l2(const std::string& spec, const std::string& camera_spec, const LiveOptions& live,
                std::unique_ptr<FrameSource>* out) {
  std::string nodes = spec.substr(5);  // after "v4l2:"
  V4l2SourceOptions options;
  const std::size_t colon = nodes.rfind(':');
  if (colon != std::string::npos) {
    if (!parsePixelFormat(nodes.substr(colon + 1), &options.colour_format))
      return Status::Error(spec + ": unknown colour format '" + nodes.substr(colon + 1) +
                           "' (yuyv mjpeg grey)");
    nodes = nodes.substr(0, colon);
  }
  const std::size_t comma = nodes.find(',');
  options.colour_device = nodes.substr(0, comma);
  if (comma != std::string::npos) options.depth_device = nodes.substr(comma + 1);
  if (options.colour_device.empty())
    return Status::Error(spec + ": expected v4l2:/dev/videoN[,/dev/videoM][:FORMAT]");
  if (camera_spec.empty())
    return Status::Error(spec + ": V4L2 reports no intrinsics; pass a camera file or preset");
  PinholeCamera camera;
  PLUMB_RETURN_IF_ERROR(cameraFromSpec(camera_spec, &camera));
  std::unique_ptr<V4l2Source> source;
  PLUMB_RETURN_IF_ERROR(V4l2Source::open(options, camera, systemV4l2Device(), &source));
  return supervised(std::move(source), live, out);
}

// paced:SPEC or paced@SPEED:SPEC around any other specification.
Status openPaced(const std::string& spec, const std::string& camera_spec,
                 std::unique_ptr<FrameSource>* out) {
  const std::size_t colon = spec.find(':');
  PacedSourceOptions options;
  if (spec[5] == '@') {
    char* end = nullptr;
    const std::string speed = spec.substr(6, colon == std::string::npos ? std::string::npos : colon - 6);
    options.speed = std::strtod(speed.c_str(), &end);
    if (speed.empty() || *end != '\0' || !(options.speed > 0))
      return Status::Error(spec + ": speed '" + speed + "' is not a positive number");
  }
  if (colon == std::string::npos || colon + 1 >= spec.size())
    return Status::Error(spec + ": expected paced:SPEC or paced@SPEED:SPEC");
  std::unique_ptr<FrameSource> inner;
  PLUMB_RETURN_IF_ERROR(openFrameSource(spec.substr(colon + 1), camera_spec, &inner));
  *out = std::make_unique<PacedSource>(std::move(inner), options);
  return Status::Ok();
}

}  // namespace

bool isSensorOrRecordingSpec(const std::string& spec) {
  return startsWith(spec, "paced:") || startsWith(spec, "paced@") || endsWith(spec, ".plumbrec") ||
         endsWith(spec, ".oni") || startsWith(spec, "openni2:") || startsWith(spec, "v4l2:");
}

Status openSensorOrRecordingSource(const std::string& spec, const std::string& camera_spec,
                                   std::unique_ptr<FrameSource>* out) {
  if (startsWith(spec, "paced:") || startsWith(spec, "paced@")) return openPaced(spec, camera_spec, out);
  if (endsWith(spec, ".plumbrec")) return openRecording(spec, camera_spec, out);
  LiveOptions live;
  std::string device;
  PLUMB_RETURN_IF_ERROR(withoutUsbSuffix(spec, &device, &live));
  if (endsWith(device, ".oni")) return openOpenNI2(device, camera_spec, live, out);
  if (startsWith(device, "openni2:")) return openOpenNI2(device.substr(8), camera_spec, live, out);
  if (startsWith(device, "v4l2:")) return openV4l2(device, camera_spec, live, out);
  return Status::Error(spec + ": not a sensor or recording specification");
}

}  // namespace plumb

#include "drivers/openni2/openni2_source.h"

#include <OpenNI.h>

#include <chrono>
#include <cmath>
#include <mutex>

#include <opencv2/imgproc.hpp>

#include "drivers/openni2/device_clock_mapper.h"

namespace plumb {
namespace {

int64_t hostNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

Status openniError(const std::string& what) {
  return Status::Error(what + ": " + openni::OpenNI::getExtendedError());
}

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Picks the exact mode (size, fps, pixel format) from what the sensor lists.
Status chooseMode(const openni::SensorInfo* info, int width, int height, int fps,
                  openni::PixelFormat format, const char* stream_name, openni::VideoMode* mode) {
  if (!info) return Status::Error(std::string("device has no ") + stream_name + " sensor");
  const openni::Array<openni::VideoMode>& modes = info->getSupportedVideoModes();
  for (int i = 0; i < modes.getSize(); ++i) {
    if (modes[i].getResolutionX() == width && modes[i].getResolutionY() == height &&
        modes[i].getFps() == fps && modes[i].getPixelFormat() == format) {
      *mode = modes[i];
      return Status::Ok();
    }
  }
  return Status::Error(std::string(stream_name) + " sensor has no " + std::to_string(width) + "x" +
                       std::to_string(height) + "@" + std::to_string(fps) + " mode");
}

class OpenNI2Source : public FrameSource {
 public:
  OpenNI2Source(const OpenNI2SourceOptions& options, const PinholeCamera* fallback)
      : options_(options), has_fallback_(fallback != nullptr) {
    if (fallback) fallback_ = *fallback;
  }
  ~OpenNI2Source() override { closeDevice(); }

  Status open() {
    const char* uri = options_.uri.empty() ? openni::ANY_DEVICE : options_.uri.c_str();
    if (device_.open(uri) != openni::STATUS_OK) {
      if (options_.uri.empty()) {
        openni::Array<openni::DeviceInfo> devices;
        openni::OpenNI::enumerateDevices(&devices);
        if (devices.getSize() == 0) return Status::Error("openni2: no OpenNI2 device connected");
      }
      return openniError("openni2:" + label() + ": cannot open");
    }
    is_file_ = device_.isFile();
    PLUMB_RETURN_IF_ERROR(startStreams().withContext("openni2:" + label()));
    return chooseCamera().withContext("openni2:" + label());
  }

  SourceResult next(RgbdImage& out) override {
    if (!device_.isValid()) {
      error_ = Status::Error(describe() + ": device not open");
      return SourceResult::kError;
    }
    if (is_file_ && played_frames_ >= file_frames_) return SourceResult::kEndOfStream;
    SourceResult r = readStream(depth_, depth_frame_);
    if (r != SourceResult::kFrame) return r;
    r = readStream(colour_, colour_frame_);
    if (r != SourceResult::kFrame) return r;
    convert(out);
    ++played_frames_;
    return SourceResult::kFrame;
  }

  const PinholeCamera& camera() const override { return camera_; }
  std::string describe() const override { return "openni2:" + label(); }
  const Status& lastError() const override { return error_; }
  bool isLive() const override { return !is_file_; }
  Status reopen() override {
    if (is_file_) return Status::Error(describe() + ": a recording cannot be reopened");
    closeDevice();
    const Status st = open();
    if (st.ok()) error_ = Status::Ok();
    return st;
  }

 private:
  std::string label() const { return options_.uri.empty() ? "first" : options_.uri; }

  Status startStreams() {
    if (depth_.create(device_, openni::SENSOR_DEPTH) != openni::STATUS_OK)
      return openniError("depth stream");
    if (colour_.create(device_, openni::SENSOR_COLOR) != openni::STATUS_OK)
      return openniError("colour stream");
    if (!is_file_) {  // a recording plays the modes it was recorded with
      openni::VideoMode mode;
      PLUMB_RETURN_IF_ERROR(chooseMode(device_.getSensorInfo(openni::SENSOR_DEPTH), options_.width,
                                       options_.height, options_.fps,
                                       openni::PIXEL_FORMAT_DEPTH_1_MM, "depth", &mode));
      if (depth_.setVideoMode(mode) != openni::STATUS_OK) return openniError("depth video mode");
      PLUMB_RETURN_IF_ERROR(chooseMode(device_.getSensorInfo(openni::SENSOR_COLOR), options_.width,
                                       options_.height, options_.fps, openni::PIXEL_FORMAT_RGB888,
                                       "colour", &mode));
      if (colour_.setVideoMode(mode) != openni::STATUS_OK) return openniError("colour video mode");
      // A camera file that describes the depth camera asks for plumb's own registration (the
      // pipeline's register stage): the device must then deliver depth as its depth camera sees it.
      if (options_.register_depth_to_colour && !softwareRegistration() &&
          device_.isImageRegistrationModeSupported(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR) &&
          device_.setImageRegistrationMode(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR) !=
              openni::STATUS_OK)
        return openniError("depth-to-colour registration");
      if (device_.setDepthColorSyncEnabled(options_.sync_depth_colour) != openni::STATUS_OK)
        return openniError("depth/colour frame sync");
      // Some devices do not implement mirroring control; their default is what we get then.
      (void)depth_.setMirroringEnabled(options_.mirror);
      (void)colour_.setMirroringEnabled(options_.mirror);
    } else if (openni::PlaybackControl* playback = device_.getPlaybackControl()) {
      (void)playback->setRepeatEnabled(false);
      file_frames_ = playback->getNumberOfFrames(depth_);
    }
    if (depth_.start() != openni::STATUS_OK) return openniError("starting depth");
    if (colour_.start() != openni::STATUS_OK) return openniError("starting colour");
    return Status::Ok();
  }

  bool softwareRegistration() const { return has_fallback_ && fallback_.depth_camera.has_value(); }

  Status chooseCamera() {
    const openni::VideoMode mode = colour_.getVideoMode();
    const double hfov = colour_.getHorizontalFieldOfView();
    const double vfov = colour_.getVerticalFieldOfView();
    const bool device_reports = std::isfinite(hfov) && std::isfinite(vfov) && hfov > 0 && vfov > 0;
    if (has_fallback_ && (options_.prefer_fallback_camera || !device_reports || softwareRegistration())) {
      camera_ = fallback_;
      camera_source_ = "camera file";
    } else if (device_reports) {
      camera_ = PinholeCamera();
      camera_.width = mode.getResolutionX();
      camera_.height = mode.getResolutionY();
      camera_.fx = camera_.width / (2.0 * std::tan(hfov / 2));
      camera_.fy = camera_.height / (2.0 * std::tan(vfov / 2));
      camera_.cx = camera_.width / 2.0 - 0.5;
      camera_.cy = camera_.height / 2.0 - 0.5;
      camera_source_ = "device field of view";
    } else {
      return Status::Error("device reports no field of view and no camera file was given");
    }
    camera_.depth_factor = 1000.0;  // PIXEL_FORMAT_DEPTH_1_MM
    const std::string problem = camera_.validate();
    return problem.empty() ? Status::Ok() : Status::Error("camera invalid: " + problem);
  }

  SourceResult readStream(openni::VideoStream& stream, openni::VideoFrameRef& frame) {
    openni::VideoStream* streams[] = {&stream};
    int ready = -1;
    const openni::Status wait =
        openni::OpenNI::waitForAnyStream(streams, 1, &ready, options_.read_timeout_ms);
    if (wait == openni::STATUS_TIME_OUT) {
      // A recording that stops producing frames before its count is exhausted has ended.
      return is_file_ ? SourceResult::kEndOfStream : SourceResult::kNoFrame;
    }
    if (wait != openni::STATUS_OK || stream.readFrame(&frame) != openni::STATUS_OK) {
      error_ = openniError(describe() + ": reading a frame failed (device disconnected?)");
      return SourceResult::kError;
    }
    return SourceResult::kFrame;
  }

  void convert(RgbdImage& out) {
    const cv::Mat rgb(colour_frame_.getHeight(), colour_frame_.getWidth(), CV_8UC3,
                      const_cast<void*>(colour_frame_.getData()),
                      static_cast<size_t>(colour_frame_.getStrideInBytes()));
    cv::cvtColor(rgb, out.bgr, cv::COLOR_RGB2BGR);
    const cv::Mat depth(depth_frame_.getHeight(), depth_frame_.getWidth(), CV_16UC1,
                        const_cast<void*>(depth_frame_.getData()),
                        static_cast<size_t>(depth_frame_.getStrideInBytes()));
    depth.copyTo(out.depth_raw);
    const int64_t now_ns = hostNowNs();
    const int64_t colour_host_ns =
        clock_.toHostNs(static_cast<int64_t>(colour_frame_.getTimestamp()) * 1000, now_ns);
    const int64_t depth_host_ns =
        static_cast<int64_t>(depth_frame_.getTimestamp()) * 1000 + clock_.offsetNs();
    out.sequence = static_cast<uint64_t>(colour_frame_.getFrameIndex());
    out.timestamp_s = colour_host_ns * 1e-9;
    out.depth_timestamp_s = depth_host_ns * 1e-9;
    out.t_sensor_ns = colour_host_ns;
    out.depth_factor = camera_.depth_factor;
  }

  void closeDevice() {
    depth_.stop();
    colour_.stop();
    depth_.destroy();
    colour_.destroy();
    if (device_.isValid()) device_.close();
  }

  OpenNI2SourceOptions options_;
  bool has_fallback_ = false;
  PinholeCamera fallback_, camera_;
  std::string camera_source_;
  openni::Device device_;
  openni::VideoStream depth_, colour_;
  openni::VideoFrameRef depth_frame_, colour_frame_;
  DeviceClockMapper clock_;
  bool is_file_ = false;
  int file_frames_ = 0;
  int played_frames_ = 0;
  Status error_;
};

}  // namespace

bool openNI2Available() { return true; }

Status initializeOpenNI2() {
  static std::once_flag once;
  static Status outcome;
  std::call_once(once, [] {
    if (openni::OpenNI::initialize() != openni::STATUS_OK)
      outcome = openniError("OpenNI2 initialisation failed");
  });
  return outcome;
}

Status listOpenNI2Devices(std::vector<OpenNI2DeviceInfo>* devices) {
  PLUMB_RETURN_IF_ERROR(initializeOpenNI2());
  openni::Array<openni::DeviceInfo> list;
  openni::OpenNI::enumerateDevices(&list);
  devices->clear();
  for (int i = 0; i < list.getSize(); ++i) {
    OpenNI2DeviceInfo info;
    info.uri = list[i].getUri();
    info.vendor = list[i].getVendor();
    info.name = list[i].getName();
    info.usb_vendor_id = list[i].getUsbVendorId();
    info.usb_product_id = list[i].getUsbProductId();
    devices->push_back(info);
  }
  return Status::Ok();
}

Status openOpenNI2Source(const OpenNI2SourceOptions& options, const PinholeCamera* fallback_camera,
                         std::unique_ptr<FrameSource>* out) {
  PLUMB_RETURN_IF_ERROR(initializeOpenNI2());
  if (endsWith(options.uri, ".oni")) {
    if (std::FILE* f = std::fopen(options.uri.c_str(), "rb")) {
      std::fclose(f);
    } else {
      return Status::Error("openni2:" + options.uri + ": cannot open the .oni file");
    }
  }
  auto source = std::make_unique<OpenNI2Source>(options, fallback_camera);
  PLUMB_RETURN_IF_ERROR(source->open());
  *out = std::move(source);
  return Status::Ok();
}

}  // namespace plumb

#pragma once
// Source specifications of the sensor and recording sources, for openFrameSource():
//   FILE.plumbrec                      our recording (brings its camera; --camera overrides it)
//   FILE.oni                           an OpenNI recording, through OpenNI2
//   openni2:first | openni2:URI        a live OpenNI2 device (camera: device FOV, else --camera)
//   v4l2:/dev/videoN[,/dev/videoM][:FORMAT]
//                                      UVC colour node [+ Z16 depth node]; FORMAT yuyv (default),
//                                      mjpeg or grey; needs --camera (V4L2 reports no intrinsics)
//   paced:SPEC | paced@SPEED:SPEC      replay SPEC at its recorded rate (x SPEED), like a sensor
//   LIVE@usb=VVVV:PPPP                 a live spec (v4l2:, openni2:) with its camera's USB VID:PID:
//                                      libusb's departure of that device is a disconnect, its
//                                      arrival reconnects (drivers/usb/usb_arrival_waker.h)
// Live sources come wrapped in a ResilientSource (reopen with backoff after errors/stalls), with
// a libusb hot-plug listener where libusb has hot-plug events.
#include <memory>
#include <string>

#include "drivers/common/frame_source.h"

namespace plumb {

bool isSensorOrRecordingSpec(const std::string& spec);
Status openSensorOrRecordingSource(const std::string& spec, const std::string& camera_spec,
                                   std::unique_ptr<FrameSource>* out);

}  // namespace plumb

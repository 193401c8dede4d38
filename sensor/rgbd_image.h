#pragma once
// RgbdImage: one raw RGB-D frame as a source delivers it, before any processing.
// Sources fill a caller-owned RgbdImage whose Mats were allocated once (same size every frame),
// so steady-state capture does not allocate.
#include <cstdint>

#include <opencv2/core.hpp>

namespace plumb {

// The largest frame timestamp plumb accepts, in seconds: 1e10 s is the year 2286 in Unix time.
// Larger stamps are nanoseconds or microseconds written as seconds, or garbage (1e300): refused
// where frames enter (lists, recordings, the API), so one such frame can neither sleep a realtime
// replay for years nor make every later (correct) frame look like a step back in time.
constexpr double kMaxTimestampS = 1e10;

struct RgbdImage {
  uint64_t sequence = 0;        // 0, 1, 2, ... in delivery order (gaps = frames the source lost)
  double timestamp_s = 0;       // sensor/recording time in seconds (TUM: the rgb timestamp)
  double depth_timestamp_s = 0; // time of the depth image paired with it
  int64_t t_sensor_ns = 0;      // host monotonic time of capture (replay: when it was delivered)
  cv::Mat bgr;                  // CV_8UC3, camera width x height
  cv::Mat depth_raw;            // CV_16UC1, raw units; metres = value / depth_factor; 0 = no reading
  double depth_factor = 5000.0;
};

}  // namespace plumb

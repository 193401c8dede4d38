#pragma once
// Helpers shared by the driver tests: seeded test frames, exact image comparison and a finite
// in-memory FrameSource (and tests/support/scratch_dir.h's ScratchDir).
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "drivers/common/frame_source.h"
#include "tests/support/scratch_dir.h"

namespace plumb::test {

// A frame of seeded noise with edge values (0, 255, 0xFFFF) so codecs see every byte value.
inline RgbdImage makeNoiseFrame(uint64_t seed, int width, int height, uint64_t sequence) {
  std::mt19937_64 rng(seed * 7919 + sequence);
  RgbdImage f;
  f.sequence = sequence;
  f.timestamp_s = 1305031102.175304 + 0.0333 * static_cast<double>(sequence);
  f.depth_timestamp_s = f.timestamp_s + 0.0021;
  f.t_sensor_ns = 1000000 + static_cast<int64_t>(sequence) * 33333333;
  f.depth_factor = 5000.0;
  f.bgr.create(height, width, CV_8UC3);
  f.depth_raw.create(height, width, CV_16UC1);
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      f.bgr.at<cv::Vec3b>(r, c) = cv::Vec3b(rng() & 0xFF, rng() & 0xFF, rng() & 0xFF);
      f.depth_raw.at<uint16_t>(r, c) = static_cast<uint16_t>(rng() & 0xFFFF);
    }
  }
  f.bgr.at<cv::Vec3b>(0, 0) = cv::Vec3b(0, 255, 0);
  f.depth_raw.at<uint16_t>(0, 0) = 0;
  f.depth_raw.at<uint16_t>(height - 1, width - 1) = 0xFFFF;
  return f;
}

inline PinholeCamera smallCamera(int width, int height) {
  PinholeCamera c;
  c.fx = 50.5; c.fy = -49.25; c.cx = width / 2.0; c.cy = height / 2.0;
  c.k1 = 0.1; c.k3 = -0.01;
  c.width = width; c.height = height;
  c.depth_factor = 5000.0;
  return c;
}

inline bool sameImage(const cv::Mat& a, const cv::Mat& b) {
  if (a.type() != b.type() || a.size() != b.size()) return false;
  for (int r = 0; r < a.rows; ++r)
    if (std::memcmp(a.ptr(r), b.ptr(r), a.cols * a.elemSize()) != 0) return false;
  return true;
}

// Finite replay of prepared frames (sequence = position), like a dataset replay.
class VectorSource : public FrameSource {
 public:
  VectorSource(std::vector<RgbdImage> frames, PinholeCamera camera)
      : frames_(std::move(frames)), camera_(camera) {}
  SourceResult next(RgbdImage& out) override {
    if (cursor_ >= frames_.size()) return SourceResult::kEndOfStream;
    const RgbdImage& f = frames_[cursor_++];
    out.sequence = f.sequence;
    out.timestamp_s = f.timestamp_s;
    out.depth_timestamp_s = f.depth_timestamp_s;
    out.t_sensor_ns = f.t_sensor_ns;
    out.depth_factor = f.depth_factor;
    f.bgr.copyTo(out.bgr);
    f.depth_raw.copyTo(out.depth_raw);
    return SourceResult::kFrame;
  }
  const PinholeCamera& camera() const override { return camera_; }
  std::string describe() const override { return "vector"; }
  const Status& lastError() const override { return error_; }

 private:
  std::vector<RgbdImage> frames_;
  PinholeCamera camera_;
  Status error_;
  std::size_t cursor_ = 0;
};

inline std::vector<RgbdImage> makeNoiseFrames(uint64_t seed, int width, int height, int count) {
  std::vector<RgbdImage> frames;
  for (int i = 0; i < count; ++i) frames.push_back(makeNoiseFrame(seed, width, height, i));
  return frames;
}

}  // namespace plumb::test

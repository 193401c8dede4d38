// Colour and depth quantisation with the synthetic sensor's noise (see sensor_model.h).
#include "drivers/synth/sensor_model.h"

#include <algorithm>
#include <cmath>

#include "drivers/synth/synth_random.h"

namespace plumb::synth {
namespace {

constexpr uint64_t kColourStream = 1, kDepthStream = 2;

inline uint8_t toByte(float v) { return static_cast<uint8_t>(std::clamp(v, 0.0f, 255.0f) + 0.5f); }

// True when a neighbour of (x, y) is nearer than z by more than the discontinuity threshold.
bool onFarSideOfEdge(const cv::Mat& depth_m, int x, int y, float z, bool wide) {
  const float threshold = 0.05f + 0.03f * z;
  const float nearer_than = z - threshold;
  for (int dy = -1; dy <= 1; ++dy) {
    if (y + dy < 0 || y + dy >= depth_m.rows) continue;
    const float* row = depth_m.ptr<float>(y + dy);
    for (int dx = -1; dx <= 1; ++dx) {
      if (x + dx >= 0 && x + dx < depth_m.cols && row[x + dx] < nearer_than) return true;
    }
  }
  if (wide) {
    const float* row = depth_m.ptr<float>(y);
    if (x >= 2 && row[x - 2] < nearer_than) return true;
    if (x + 2 < depth_m.cols && row[x + 2] < nearer_than) return true;
  }
  return false;
}

}  // namespace

void quantiseColour(const cv::Mat& colour_bgr, const SensorModelOptions& options, uint64_t seed, int frame,
                    cv::Mat& bgr_out) {
  bgr_out.create(colour_bgr.rows, colour_bgr.cols, CV_8UC3);  // no-op when already that shape
  const float sigma = static_cast<float>(options.pixel_noise_sigma);
  const uint64_t frame_seed = hash3(seed, kColourStream, static_cast<uint64_t>(frame));
  for (int y = 0; y < colour_bgr.rows; ++y) {
    const cv::Vec3f* in = colour_bgr.ptr<cv::Vec3f>(y);
    cv::Vec3b* out = bgr_out.ptr<cv::Vec3b>(y);
    for (int x = 0; x < colour_bgr.cols; ++x) {
      if (sigma <= 0) {
        for (int k = 0; k < 3; ++k) out[x][k] = toByte(in[x][k]);
        continue;
      }
      const uint64_t bits = mix64(frame_seed + static_cast<uint64_t>(y) * colour_bgr.cols + x);
      for (int k = 0; k < 3; ++k) out[x][k] = toByte(in[x][k] + sigma * gaussianFromBits(bits >> (16 * k)));
    }
  }
}

void quantiseDepth(const cv::Mat& depth_m, const SensorModelOptions& options, uint64_t seed, int frame,
                   cv::Mat& depth_raw_out) {
  depth_raw_out.create(depth_m.rows, depth_m.cols, CV_16UC1);
  const uint64_t frame_seed = hash3(seed, kDepthStream, static_cast<uint64_t>(frame));
  const double max_raw = 65535.0;
  for (int y = 0; y < depth_m.rows; ++y) {
    const float* in = depth_m.ptr<float>(y);
    uint16_t* out = depth_raw_out.ptr<uint16_t>(y);
    for (int x = 0; x < depth_m.cols; ++x) {
      const float z = in[x];
      if (!(z >= options.min_depth_m && z <= options.max_depth_m)) {  // also catches +inf
        out[x] = 0;
        continue;
      }
      const uint64_t bits = mix64(frame_seed + static_cast<uint64_t>(y) * depth_m.cols + x);
      if (options.depth_edge_holes && onFarSideOfEdge(depth_m, x, y, z, (bits >> 16) & 1)) {
        out[x] = 0;
        continue;
      }
      double measured = z;
      if (options.depth_noise) measured += options.depth_noise_k * z * z * gaussianFromBits(bits);
      const double raw = measured * options.depth_factor + 0.5;
      out[x] = raw <= 1.0 ? 0 : static_cast<uint16_t>(std::min(raw, max_raw));
    }
  }
}

}  // namespace plumb::synth

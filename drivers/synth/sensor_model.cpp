// Colour and depth quantisation with the synthetic sensor's noise (see sensor_model.h).
#include "drivers/synth/sensor_model.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core/hal/intrin.hpp>

#include "drivers/synth/synth_random.h"

namespace plumb::synth {
namespace {

constexpr uint64_t kColourStream = 1, kDepthStream = 2;

// v >= 0 after the clamp, where + 0.5 and truncation round correctly; lround would change the
// rendered images' bytes in rare float ties.
inline uint8_t toByte(float v) {
  return static_cast<uint8_t>(std::clamp(v, 0.0f, 255.0f) + 0.5f);  // NOLINT(bugprone-incorrect-roundings)
}

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

// toByte over n floats (a noise-free colour row, channels interleaved).
void quantiseRow(const float* in, uint8_t* out, int n) {
  int i = 0;
#if CV_SIMD128
  // clamp, + 0.5, truncate: the same float operations as toByte, four lanes at a time.
  const cv::v_float32x4 zero = cv::v_setzero_f32(), top = cv::v_setall_f32(255.0f), half = cv::v_setall_f32(0.5f);
  auto convert = [&](int at) { return cv::v_trunc(cv::v_min(cv::v_max(cv::v_load(in + at), zero), top) + half); };
  for (; i + 16 <= n; i += 16) {
    const cv::v_int16x8 low = cv::v_pack(convert(i), convert(i + 4)), high = cv::v_pack(convert(i + 8), convert(i + 12));
    cv::v_store(out + i, cv::v_pack_u(low, high));
  }
#endif
  for (; i < n; ++i) out[i] = toByte(in[i]);
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
    if (sigma <= 0) {
      quantiseRow(colour_bgr.ptr<float>(y), bgr_out.ptr<uint8_t>(y), 3 * colour_bgr.cols);
      continue;
    }
    for (int x = 0; x < colour_bgr.cols; ++x) {
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
      if (!options.depth_edge_holes && !options.depth_noise) {  // exact: no random bits needed
        const double raw = static_cast<double>(z) * options.depth_factor + 0.5;
        out[x] = raw <= 1.0 ? 0 : static_cast<uint16_t>(std::min(raw, max_raw));
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

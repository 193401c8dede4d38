// The synthetic sensor model: depth noise sigma grows like k z^2, pixel noise has the requested
// sigma, holes sit only on the far side of depth edges.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "drivers/synth/synthetic_scene.h"

namespace plumb {
namespace {

struct Pair {
  RgbdImage clean, noisy;
};

Pair renderPair(SynthOptions noisy_options, int frame) {
  SynthOptions clean_options = noisy_options;
  clean_options.pixel_noise_sigma = 0;
  clean_options.depth_noise = false;
  clean_options.depth_edge_holes = false;
  std::unique_ptr<SyntheticScene> clean, noisy;
  EXPECT_TRUE(SyntheticScene::create(clean_options, &clean).ok());
  EXPECT_TRUE(SyntheticScene::create(noisy_options, &noisy).ok());
  Pair pair;
  EXPECT_TRUE(clean->render(frame, pair.clean).ok());
  EXPECT_TRUE(noisy->render(frame, pair.noisy).ok());
  return pair;
}

TEST(SynthNoise, DepthSigmaGrowsWithDepthSquared) {
  SynthOptions options;
  options.preset = "low_texture";
  options.depth_noise = true;
  options.depth_noise_k = 0.0014;
  // Pool a few views to fill depth bins from 1 m to 5 m.
  constexpr int kBins = 4;  // [1,2) [2,3) [3,4) [4,5) m
  double sum_sq[kBins] = {}, sum_z2sq[kBins] = {};
  int count[kBins] = {};
  for (int frame : {0, 150, 300, 450}) {
    const Pair pair = renderPair(options, frame);
    for (int y = 0; y < 480; ++y)
      for (int x = 0; x < 640; ++x) {
        const uint16_t clean = pair.clean.depth_raw.at<uint16_t>(y, x), noisy = pair.noisy.depth_raw.at<uint16_t>(y, x);
        if (clean == 0 || noisy == 0) continue;
        const double z = clean / 5000.0;
        const int bin = static_cast<int>(z) - 1;
        if (bin < 0 || bin >= kBins) continue;
        const double error = (static_cast<double>(noisy) - clean) / 5000.0;
        sum_sq[bin] += error * error;
        sum_z2sq[bin] += z * z * z * z;  // expected variance is k^2 z^4
        ++count[bin];
      }
  }
  double sigma[kBins];
  for (int b = 0; b < kBins; ++b) {
    ASSERT_GT(count[b], 5000) << "bin " << b;
    sigma[b] = std::sqrt(sum_sq[b] / count[b]);
    const double expected = options.depth_noise_k * std::sqrt(sum_z2sq[b] / count[b]);
    std::printf("depth %d-%d m: sigma %.5f m, k z^2 %.5f m\n", b + 1, b + 2, sigma[b], expected);
    EXPECT_NEAR(sigma[b] / expected, 1.0, 0.06) << "depth bin " << b + 1 << "-" << b + 2 << " m";
  }
  // Quadratic, not linear: from ~1.5 m to ~4.5 m sigma grows ~9x (linear would be 3x).
  EXPECT_GT(sigma[3] / sigma[0], 6.0);
}

TEST(SynthNoise, PixelNoiseHasTheRequestedSigmaAndZeroMean) {
  SynthOptions options;
  options.preset = "low_texture";
  options.pixel_noise_sigma = 4.0;
  const Pair pair = renderPair(options, 20);
  double sum = 0, sum_sq = 0;
  int n = 0;
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x)
      for (int k = 0; k < 3; ++k) {
        const int clean = pair.clean.bgr.at<cv::Vec3b>(y, x)[k];
        if (clean < 20 || clean > 235) continue;  // away from clamping
        const double d = pair.noisy.bgr.at<cv::Vec3b>(y, x)[k] - clean;
        sum += d;
        sum_sq += d * d;
        ++n;
      }
  ASSERT_GT(n, 100000);
  const double mean = sum / n;
  EXPECT_NEAR(mean, 0.0, 0.05);
  // Rounding to integers adds 1/12 to the variance.
  EXPECT_NEAR(std::sqrt(sum_sq / n - mean * mean), std::sqrt(16.0 + 1.0 / 12), 0.1);
  EXPECT_TRUE(cv::countNonZero(pair.clean.depth_raw != pair.noisy.depth_raw) == 0) << "pixel noise only";
}

TEST(SynthNoise, HolesOnlyOnTheFarSideOfDepthEdges) {
  SynthOptions options;
  options.preset = "textured";
  options.depth_edge_holes = true;
  const Pair pair = renderPair(options, 40);
  int holes = 0, valid = 0, unexplained = 0;
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x) {
      const uint16_t clean = pair.clean.depth_raw.at<uint16_t>(y, x);
      if (clean == 0) continue;
      ++valid;
      const uint16_t noisy = pair.noisy.depth_raw.at<uint16_t>(y, x);
      if (noisy != 0) {
        EXPECT_EQ(noisy, clean) << "holes alone must not change other depths";
        continue;
      }
      ++holes;
      // A nearer surface within 2 px must explain the hole.
      bool nearer = false;
      const double z = clean / 5000.0;
      for (int dy = -2; dy <= 2 && !nearer; ++dy)
        for (int dx = -2; dx <= 2 && !nearer; ++dx) {
          const int u = x + dx, v = y + dy;
          if (u < 0 || v < 0 || u >= 640 || v >= 480) continue;
          const uint16_t other = pair.clean.depth_raw.at<uint16_t>(v, u);
          nearer = other != 0 && other / 5000.0 < z - 0.05;
        }
      unexplained += !nearer;
    }
  std::printf("holes: %d of %d valid pixels\n", holes, valid);
  EXPECT_EQ(unexplained, 0);
  EXPECT_GT(holes, 0.002 * valid) << "the frame has depth edges, so it must have holes";
  EXPECT_LT(holes, 0.08 * valid);
}

TEST(SynthNoise, RangeLimitsReadZero) {
  SynthOptions options;
  options.preset = "low_texture";
  options.max_depth_m = 3.0;
  options.min_depth_m = 1.5;
  std::unique_ptr<SyntheticScene> scene;
  ASSERT_TRUE(SyntheticScene::create(options, &scene).ok());
  RgbdImage frame;
  ASSERT_TRUE(scene->render(0, frame).ok());
  double lo = 1e9, hi = 0;
  int zeros = 0;
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x) {
      const uint16_t raw = frame.depth_raw.at<uint16_t>(y, x);
      if (raw == 0) {
        ++zeros;
        continue;
      }
      lo = std::min(lo, raw / 5000.0);
      hi = std::max(hi, raw / 5000.0);
    }
  EXPECT_GE(lo, 1.5 - 1e-4);
  EXPECT_LE(hi, 3.0 + 1e-4);
  EXPECT_GT(zeros, 1000);
}

}  // namespace
}  // namespace plumb

// LineSegmentDetector's fast paths against plain definitions: the neighbour masks (SSE2 where
// built, the portable multiply) against a byte-by-byte 3x3 read, and the whole detector (SIMD
// gradient, 16-state candidate scan, mask-driven region growing, the rejections before the fit)
// against a scalar oracle written from the header's description with the same float and double
// operations. The detector claims to give exactly the oracle's segments, so the comparison is of
// bits, not a tolerance.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "pipeline/frontend/line_segment_detector.h"
#include "pipeline/frontend/lsd_kernels.h"

namespace plumb {
namespace {

// The mask's definition: bit 4 * (dy + 1) + (dx + 1) is set when that neighbour's state is free.
uint32_t neighbourMaskDefinition(const uint8_t* state, int p, int w) {
  uint32_t mask = 0;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      if (state[p + dy * w + dx] == kLsdFree) mask |= 1u << (4 * (dy + 1) + (dx + 1));
    }
  }
  return mask;
}

TEST(LsdKernels, NeighbourMasksEqualTheDefinitionOnRandomStates) {
  std::mt19937 rng(7);
  for (int w : {1, 2, 3, 8, 17, 309}) {
    // Rows of w states plus the bytes the word reads touch before and after.
    std::vector<uint8_t> state(static_cast<size_t>(w) * 7 + 8);
    for (double free_fraction : {0.0, 0.33, 0.9, 1.0}) {
      std::bernoulli_distribution is_free(free_fraction);
      for (int trial = 0; trial < 50; ++trial) {
        for (uint8_t& s : state) s = is_free(rng) ? kLsdFree : kLsdUsed;
        for (int p = w + 1; p + w + 2 < static_cast<int>(state.size()); ++p) {
          const uint32_t expected = neighbourMaskDefinition(state.data(), p, w);
          ASSERT_EQ(lsdNeighbourMaskPortable(state.data(), p, w), expected) << "w " << w << " p " << p;
#if defined(__SSE2__)
          ASSERT_EQ(lsdNeighbourMaskSse2(state.data(), p, w), expected) << "w " << w << " p " << p;
#endif
          ASSERT_EQ(lsdNeighbourMask(state.data(), p, w), expected);
        }
      }
    }
  }
}

// The detector, written plainly: scalar gradient, a stable sort of the candidates by magnitude
// bin, region growing with a 3x3 loop and edge tests, the rectangle fit with every test after it.
std::vector<DetectedSegment> oracleDetect(const cv::Mat& image, float min_length, int capacity,
                                          const LineSegmentDetectorOptions& options = {}) {
  const int w = image.cols, h = image.rows;
  const float tau = options.angle_tolerance_deg * static_cast<float>(M_PI) / 180.f;
  const float threshold = options.quantization / std::sin(tau);
  const float cos_tau = std::cos(tau);
  std::vector<float> mag(w * h, 0.f), ux(w * h, 0.f), uy(w * h, 0.f);
  std::vector<bool> free_pixel(w * h, false);
  float max_m = 0;
  for (int y = 0; y + 1 < h; ++y) {
    for (int x = 0; x + 1 < w; ++x) {
      const int a = image.at<uint8_t>(y, x), b = image.at<uint8_t>(y, x + 1);
      const int c = image.at<uint8_t>(y + 1, x), d = image.at<uint8_t>(y + 1, x + 1);
      const float gx = 0.5f * static_cast<float>(b + d - a - c);
      const float gy = 0.5f * static_cast<float>(c + d - a - b);
      const float m = std::sqrt(gx * gx + gy * gy);
      const int i = y * w + x;
      mag[i] = m;
      const float inv = m > 0 ? 1.f / m : 0.f;
      ux[i] = gx * inv;
      uy[i] = gy * inv;
      free_pixel[i] = m > threshold;
      max_m = std::max(max_m, m);
    }
  }
  std::vector<DetectedSegment> out;
  if (max_m <= threshold) return out;
  const float bin_scale = 1023 / max_m;
  std::vector<std::pair<int, int>> order;  // (bin, pixel), strongest bin first, raster order within
  for (int i = 0; i < w * h; ++i) {
    if (free_pixel[i]) order.emplace_back(1023 - static_cast<int>(mag[i] * bin_scale), i);
  }
  std::stable_sort(order.begin(), order.end(), [](const auto& l, const auto& r) { return l.first < r.first; });
  for (const auto& [bin, seed] : order) {
    if (static_cast<int>(out.size()) >= capacity) break;
    if (!free_pixel[seed]) continue;
    free_pixel[seed] = false;
    std::vector<int> region{seed};
    float sum_x = ux[seed], sum_y = uy[seed];
    float bound = cos_tau * std::sqrt(sum_x * sum_x + sum_y * sum_y);
    for (size_t r = 0; r < region.size(); ++r) {
      const int px = region[r] % w, py = region[r] / w;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = px + dx, y = py + dy;
          if (x < 0 || y < 0 || x >= w || y >= h) continue;
          const int q = y * w + x;
          if (!free_pixel[q] || ux[q] * sum_x + uy[q] * sum_y < bound) continue;
          free_pixel[q] = false;
          region.push_back(q);
          sum_x += ux[q];
          sum_y += uy[q];
          bound = cos_tau * std::sqrt(sum_x * sum_x + sum_y * sum_y);
        }
      }
    }
    const int size = static_cast<int>(region.size());
    if (size < 4) continue;
    double sw = 0, cx = 0, cy = 0, gx = 0, gy = 0;
    for (int p : region) {
      const double m = mag[p];
      sw += m;
      cx += m * (p % w);
      cy += m * (p / w);
      gx += m * ux[p];
      gy += m * uy[p];
    }
    cx /= sw;
    cy /= sw;
    double sxx = 0, syy = 0, sxy = 0;
    for (int p : region) {
      const double m = mag[p], dx = p % w - cx, dy = p / w - cy;
      sxx += m * dx * dx;
      syy += m * dy * dy;
      sxy += m * dx * dy;
    }
    const double theta = 0.5 * std::atan2(2 * sxy, sxx - syy);
    double dir_x = std::cos(theta), dir_y = std::sin(theta);
    if (dir_x * gy - dir_y * gx > 0) dir_x = -dir_x, dir_y = -dir_y;
    double l_min = 1e30, l_max = -1e30, across2 = 0;
    for (int p : region) {
      const double dx = p % w - cx, dy = p / w - cy;
      const double along = dx * dir_x + dy * dir_y, across = -dx * dir_y + dy * dir_x;
      l_min = std::min(l_min, along);
      l_max = std::max(l_max, along);
      across2 += mag[p] * across * across;
    }
    const double length = l_max - l_min + 1;
    if (length < min_length || std::sqrt(across2 / sw) > options.max_rms_width_px ||
        size > options.max_thickness_px * length) {
      continue;
    }
    DetectedSegment s;
    s.x0 = static_cast<float>(cx + 0.5 + l_min * dir_x);
    s.y0 = static_cast<float>(cy + 0.5 + l_min * dir_y);
    s.x1 = static_cast<float>(cx + 0.5 + l_max * dir_x);
    s.y1 = static_cast<float>(cy + 0.5 + l_max * dir_y);
    s.length = static_cast<float>(l_max - l_min);
    s.mean_gradient = static_cast<float>(sw / size);
    out.push_back(s);
  }
  return out;
}

// Smoothed noise with edges: rectangles, lines at several angles and a circle (curved edges the
// fit must reject), some touching the image border.
cv::Mat edgeImage(int width, int height, uint64_t seed, double noise_sigma) {
  cv::Mat img(height, width, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(img, cv::RNG::NORMAL, 120, noise_sigma);
  cv::rectangle(img, cv::Rect(width / 6, height / 5, width / 3, height / 3), cv::Scalar(220), cv::FILLED);
  cv::rectangle(img, cv::Rect(0, height / 2, width / 4, height / 2), cv::Scalar(30), cv::FILLED);
  for (int i = 0; i < 6; ++i) {
    const cv::Point a(rng.uniform(0, width), rng.uniform(0, height)), b(rng.uniform(0, width), rng.uniform(0, height));
    cv::line(img, a, b, cv::Scalar(rng.uniform(0, 256)), rng.uniform(1, 4));
  }
  cv::circle(img, cv::Point(2 * width / 3, height / 2), std::min(width, height) / 4, cv::Scalar(200), 2);
  cv::GaussianBlur(img, img, cv::Size(3, 3), 0.8);
  return img;
}

void expectSameSegments(const cv::Mat& image, float min_length, int capacity) {
  LineSegmentDetector detector(image.cols, image.rows);
  std::vector<DetectedSegment> got(std::max(capacity, 1));
  const int n = detector.detect(image, min_length, got.data(), capacity);
  const std::vector<DetectedSegment> expected = oracleDetect(image, min_length, capacity);
  ASSERT_EQ(n, static_cast<int>(expected.size())) << image.cols << "x" << image.rows << " min_length " << min_length;
  for (int i = 0; i < n; ++i) {
    EXPECT_EQ(0, std::memcmp(&got[i], &expected[i], sizeof(DetectedSegment)))
        << "segment " << i << ": (" << got[i].x0 << ", " << got[i].y0 << ") - (" << got[i].x1 << ", " << got[i].y1
        << ") against (" << expected[i].x0 << ", " << expected[i].y0 << ") - (" << expected[i].x1 << ", "
        << expected[i].y1 << ")";
  }
}

TEST(LsdKernels, DetectorEqualsTheScalarOracleOnEdgeImages) {
  int segments = 0;
  // Widths that are and are not multiples of the 8- and 16-pixel steps; the pyramid level's size.
  for (const cv::Size size : {cv::Size(309, 232), cv::Size(64, 48), cv::Size(61, 37), cv::Size(7, 9), cv::Size(17, 3)}) {
    for (uint64_t seed = 1; seed <= 3; ++seed) {
      for (double noise : {2.0, 12.0}) {
        const cv::Mat image = edgeImage(size.width, size.height, seed, noise);
        SCOPED_TRACE(testing::Message() << size << " seed " << seed << " noise " << noise);
        for (float min_length : {4.f, 10.9f}) expectSameSegments(image, min_length, 512);
        expectSameSegments(image, 4.f, 3);  // the capacity stops detection early
        LineSegmentDetector detector(size.width, size.height);
        std::vector<DetectedSegment> out(512);
        segments += detector.detect(image, 4.f, out.data(), 512);
      }
    }
  }
  EXPECT_GT(segments, 100) << "the images must give segments for the comparison to mean anything";
}

TEST(LsdKernels, DetectorEqualsTheScalarOracleOnNoiseAndFlatImages) {
  cv::Mat noise(120, 157, CV_8UC1);
  cv::RNG rng(11);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  expectSameSegments(noise, 4.f, 512);
  expectSameSegments(cv::Mat(40, 50, CV_8UC1, cv::Scalar(77)), 4.f, 512);  // no gradient: nothing
  // Saturated steps: the largest gradients (|2 gx| = 510) and a one-pixel checkerboard.
  cv::Mat steps(50, 83, CV_8UC1, cv::Scalar(0));
  steps(cv::Rect(20, 0, 30, 50)).setTo(255);
  steps(cv::Rect(0, 25, 83, 10)).setTo(255);
  for (int y = 40; y < 50; ++y)
    for (int x = 60; x < 83; ++x) steps.at<uint8_t>(y, x) = ((x + y) & 1) ? 255 : 0;
  expectSameSegments(steps, 4.f, 512);
  // A smaller image after a larger one in the same detector (buffers sized for the larger).
  LineSegmentDetector detector(309, 232);
  std::vector<DetectedSegment> out(512);
  detector.detect(edgeImage(309, 232, 5, 4.0), 4.f, out.data(), 512);
  const cv::Mat small = edgeImage(100, 80, 6, 4.0);
  const int n = detector.detect(small, 4.f, out.data(), 512);
  const std::vector<DetectedSegment> expected = oracleDetect(small, 4.f, 512);
  ASSERT_EQ(n, static_cast<int>(expected.size()));
  for (int i = 0; i < n; ++i) EXPECT_EQ(0, std::memcmp(&out[i], &expected[i], sizeof(DetectedSegment))) << i;
}

}  // namespace
}  // namespace plumb

#include "pipeline/orb_fast.h"

#include <algorithm>
#include <cstring>

#include <opencv2/core/hal/intrin.hpp>

namespace plumb {
namespace {

// The 16 circle pixels, clockwise from the top.
constexpr int kCircleX[16] = {0, 1, 2, 3, 3, 3, 2, 1, 0, -1, -2, -3, -3, -3, -2, -1};
constexpr int kCircleY[16] = {-3, -3, -2, -1, 0, 1, 2, 3, 3, 3, 2, 1, 0, -1, -2, -3};

}  // namespace

int fastScore(const uint8_t* p, int stride) {
  int d[32];
  const int centre = *p;
  for (int k = 0; k < 16; ++k) d[k] = d[k + 16] = p[kCircleY[k] * stride + kCircleX[k]] - centre;
  int best = 0;
  for (int start = 0; start < 16; ++start) {
    int min_bright = 255, min_dark = 255;
    for (int k = start; k < start + 9; ++k) {
      min_bright = std::min(min_bright, d[k]);
      min_dark = std::min(min_dark, -d[k]);
    }
    best = std::max(best, std::max(min_bright, min_dark));
  }
  return best;
}

FastDetector::FastDetector(int max_width, int max_height, int capacity)
    : capacity_(capacity), score_(max_height, max_width, CV_8UC1, cv::Scalar(0)),
      storage_(new FastCorner[2 * static_cast<size_t>(capacity)]) {
  raw_ = storage_.get();
  kept_ = storage_.get() + capacity;
}

int FastDetector::detect(const cv::Mat& image, int threshold, int border) {
  CV_Assert(image.type() == CV_8UC1 && image.cols <= score_.cols && image.rows <= score_.rows);
  border = std::max(border, 3);
  const int stride = static_cast<int>(image.step[0]);
  const int x_end = image.cols - border, y_end = image.rows - border;
  dropped_ = 0;
  int num_raw = 0;
  const int score_stride = static_cast<int>(score_.step[0]);
  for (int y = border - 1; y <= y_end; ++y) {
    std::memset(score_.ptr<uint8_t>(y) + border - 1, 0, static_cast<size_t>(x_end - border + 2));
  }

  const int compass[4] = {-3 * stride, 3, 3 * stride, -3};
  const cv::v_uint8x16 t = cv::v_setall_u8(static_cast<uint8_t>(threshold));
  const cv::v_uint8x16 one = cv::v_setall_u8(1), two = cv::v_setall_u8(2);
  for (int y = border; y < y_end; ++y) {
    const uint8_t* row = image.ptr<uint8_t>(y);
    uint8_t* score_row = score_.ptr<uint8_t>(y);
    int x = border;
    // Rejection test 16 pixels at a time: an arc of 9 of 16 always covers at least two of the
    // four compass pixels, so a corner needs >= 2 of them brighter (or darker) than the centre.
    for (; x + 16 <= x_end; x += 16) {
      const cv::v_uint8x16 c = cv::v_load(row + x);
      const cv::v_uint8x16 hi = c + t, lo = c - t;  // saturating
      cv::v_uint8x16 bright = cv::v_setzero_u8(), dark = cv::v_setzero_u8();
      for (int k = 0; k < 4; ++k) {
        const cv::v_uint8x16 q = cv::v_load(row + x + compass[k]);
        bright += (q > hi) & one;
        dark += (q < lo) & one;
      }
      const cv::v_uint8x16 maybe = (bright >= two) | (dark >= two);
      if (!cv::v_check_any(maybe)) continue;
      int mask = cv::v_signmask(maybe);
      while (mask) {
        const int lane = __builtin_ctz(mask);
        mask &= mask - 1;
        const int score = fastScore(row + x + lane, stride);
        if (score > threshold) {
          score_row[x + lane] = static_cast<uint8_t>(std::min(score, 255));
          if (num_raw < capacity_) raw_[num_raw++] = FastCorner{int16_t(x + lane), int16_t(y), uint8_t(std::min(score, 255))};
          else ++dropped_;
        }
      }
    }
    for (; x < x_end; ++x) {  // tail
      const int score = fastScore(row + x, stride);
      if (score > threshold) {
        score_row[x] = static_cast<uint8_t>(std::min(score, 255));
        if (num_raw < capacity_) raw_[num_raw++] = FastCorner{int16_t(x), int16_t(y), uint8_t(std::min(score, 255))};
        else ++dropped_;
      }
    }
  }

  // 3x3 non-maximum suppression; a tie goes to the earlier pixel in raster order.
  int num_kept = 0;
  for (int i = 0; i < num_raw; ++i) {
    const FastCorner c = raw_[i];
    const uint8_t* s = score_.ptr<uint8_t>(c.y) + c.x;
    const int v = *s;
    const bool is_max = v > s[-score_stride - 1] && v > s[-score_stride] && v > s[-score_stride + 1] &&
                        v > s[-1] && v >= s[1] && v >= s[score_stride - 1] && v >= s[score_stride] &&
                        v >= s[score_stride + 1];
    if (is_max) kept_[num_kept++] = c;
  }
  return num_kept;
}

}  // namespace plumb

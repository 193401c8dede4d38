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
  // Sliding minimum / maximum over windows of 9 by doubling (2, 4, 8, then +1): 4 passes of 16
  // instead of 16 x 9 comparisons. Bright arcs need the minimum difference, dark arcs the maximum.
  int d[32], lo2[32], hi2[32], lo4[32], hi4[32];
  const int centre = *p;
  for (int k = 0; k < 16; ++k) d[k] = d[k + 16] = p[kCircleY[k] * stride + kCircleX[k]] - centre;
  for (int k = 0; k < 31; ++k) {
    lo2[k] = std::min(d[k], d[k + 1]);
    hi2[k] = std::max(d[k], d[k + 1]);
  }
  for (int k = 0; k < 29; ++k) {
    lo4[k] = std::min(lo2[k], lo2[k + 2]);
    hi4[k] = std::max(hi2[k], hi2[k + 2]);
  }
  int best = 0;
  for (int k = 0; k < 16; ++k) {
    const int lo9 = std::min(std::min(lo4[k], lo4[k + 4]), d[k + 8]);
    const int hi9 = std::max(std::max(hi4[k], hi4[k + 4]), d[k + 8]);
    best = std::max(best, std::max(lo9, -hi9));
  }
  return best;
}

FastDetector::FastDetector(int max_width, int max_height, int capacity)
    : capacity_(capacity), score_(max_height, max_width, CV_8UC1, cv::Scalar(0)),
      storage_(new FastCorner[2 * static_cast<size_t>(capacity)]) {
  raw_ = storage_.get();
  kept_ = storage_.get() + capacity;
}

void FastDetector::begin(const cv::Mat& image, int border) {
  CV_Assert(image.type() == CV_8UC1 && image.cols <= score_.cols && image.rows <= score_.rows);
  image_ = image;
  border_ = std::max(border, 3);
  dropped_ = 0;
  num_raw_ = 0;
  const int x_end = image.cols - border_, y_end = image.rows - border_;
  for (int y = border_ - 1; y <= y_end; ++y) {
    std::memset(score_.ptr<uint8_t>(y) + border_ - 1, 0, static_cast<size_t>(x_end - border_ + 2));
  }
}

void FastDetector::scan(int threshold, int x0, int y0, int x1, int y1) {
  const cv::Mat& image = image_;
  const int stride = static_cast<int>(image.step[0]);
  x0 = std::max(x0, border_);
  y0 = std::max(y0, border_);
  const int x_end = std::min(x1, image.cols - border_), y_end = std::min(y1, image.rows - border_);
  threshold = std::clamp(threshold, 1, 254);

  const int compass[4] = {-3 * stride, 3, 3 * stride, -3};
  int circle[16];
  for (int k = 0; k < 16; ++k) circle[k] = kCircleY[k] * stride + kCircleX[k];
  const cv::v_uint8x16 t = cv::v_setall_u8(static_cast<uint8_t>(threshold));
  const cv::v_uint8x16 one = cv::v_setall_u8(1), two = cv::v_setall_u8(2), four = cv::v_setall_u8(4);
  auto record = [&](uint8_t* score_row, int x, int y, int score) {
    if (score <= threshold) return;
    score_row[x] = static_cast<uint8_t>(std::min(score, 255));
    if (num_raw_ < capacity_) raw_[num_raw_++] = FastCorner{int16_t(x), int16_t(y), uint8_t(std::min(score, 255))};
    else ++dropped_;
  };
  for (int y = y0; y < y_end; ++y) {
    const uint8_t* row = image.ptr<uint8_t>(y);
    uint8_t* score_row = score_.ptr<uint8_t>(y);
    // One block of 16 pixels starting at bx; lanes below `first_lane` were done already.
    auto block = [&](int bx, int first_lane) {
      const cv::v_uint8x16 c = cv::v_load(row + bx);
      const cv::v_uint8x16 hi = c + t, lo = c - t;  // saturating
      // Rejection test: an arc of 9 of 16 always covers at least two of the four compass
      // pixels, so a corner needs >= 2 of them brighter (or darker) than the centre.
      cv::v_uint8x16 bright = cv::v_setzero_u8(), dark = cv::v_setzero_u8();
      for (int k = 0; k < 4; ++k) {
        const cv::v_uint8x16 q = cv::v_load(row + bx + compass[k]);
        bright += (q > hi) & one;
        dark += (q < lo) & one;
      }
      cv::v_uint8x16 maybe = (bright >= two) | (dark >= two);
      if (!cv::v_check_any(maybe)) return;
      // Second filter on the four diagonal-ish even pixels: an arc of 9 covers >= 4 of the 8 even
      // circle positions, so a corner needs >= 4 of them on one side.
      for (int k = 2; k < 16; k += 4) {
        const cv::v_uint8x16 q = cv::v_load(row + bx + circle[k]);
        bright += (q > hi) & one;
        dark += (q < lo) & one;
      }
      maybe = (bright >= four) | (dark >= four);
      if (!cv::v_check_any(maybe)) return;
      // Third filter, the full count: an arc of 9 needs >= 9 of all 16 pixels on one side. It
      // also tells which sides can still have a corner, so only those get scored below.
      cv::v_uint8x16 q[16];
      for (int k = 0; k < 16; ++k) q[k] = cv::v_load(row + bx + circle[k]);
      for (int k = 1; k < 16; k += 2) {
        bright += (q[k] > hi) & one;
        dark += (q[k] < lo) & one;
      }
      const cv::v_uint8x16 nine = cv::v_setall_u8(9);
      const cv::v_uint8x16 maybe_bright = (bright >= nine) & maybe, maybe_dark = (dark >= nine) & maybe;
      const bool any_bright = cv::v_check_any(maybe_bright), any_dark = cv::v_check_any(maybe_dark);
      if (!any_bright && !any_dark) return;
      maybe = maybe_bright | maybe_dark;
      // Score in saturating u8 arithmetic: with b_k = sat(I_k - c) and e_k = sat(c - I_k), the
      // score is the max over the 16 arcs of 9 of min(b) (bright side) or min(e) (dark side); a
      // pixel is a corner exactly when its score exceeds the threshold (the segment test). Arcs
      // of 9 of 16 cannot be bright and dark at once, so a corner's score is that of the side
      // that passed the count: a side no lane can pass is skipped without changing any score.
      auto sideScore = [](const cv::v_uint8x16* diff, cv::v_uint8x16 score) {
        cv::v_uint8x16 d2[31];
        for (int k = 0; k < 31; ++k) d2[k] = cv::v_min(diff[k & 15], diff[(k + 1) & 15]);
        for (int k = 0; k < 16; ++k) {
          const cv::v_uint8x16 d4a = cv::v_min(d2[k], d2[k + 2]), d4b = cv::v_min(d2[k + 4], d2[k + 6]);
          score = cv::v_max(score, cv::v_min(cv::v_min(d4a, d4b), diff[(k + 8) & 15]));
        }
        return score;
      };
      cv::v_uint8x16 score = cv::v_setzero_u8();
      cv::v_uint8x16 diff[16];
      if (any_bright) {
        for (int k = 0; k < 16; ++k) diff[k] = q[k] - c;
        score = sideScore(diff, score);
      }
      if (any_dark) {
        for (int k = 0; k < 16; ++k) diff[k] = c - q[k];
        score = sideScore(diff, score);
      }
      int mask = cv::v_signmask((score > t) & maybe) & (0xFFFF << first_lane);
      if (!mask) return;
      uint8_t lane_score[16];
      cv::v_store(lane_score, score);
      while (mask) {
        const int lane = __builtin_ctz(mask);
        mask &= mask - 1;
        record(score_row, bx + lane, y, lane_score[lane]);
      }
    };
    int x = x0;
    for (; x + 16 <= x_end; x += 16) block(x, 0);
    if (x < x_end && x_end - x0 >= 16) {
      block(x_end - 16, 16 - (x_end - x));  // overlapping last block, only its new lanes
      x = x_end;
    }
    for (; x < x_end; ++x) record(score_row, x, y, fastScore(row + x, stride));  // tail
  }
}

int FastDetector::suppress() {
  // 3x3 non-maximum suppression; a tie goes to the earlier pixel in raster order.
  const int score_stride = static_cast<int>(score_.step[0]);
  int num_kept = 0;
  for (int i = 0; i < num_raw_; ++i) {
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

#include "pipeline/frontend/orb_fast.h"

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
      storage_(2 * static_cast<size_t>(capacity)) {
  raw_ = storage_.data();
  kept_ = storage_.data() + capacity;
}

void FastDetector::begin(const cv::Mat& image, int border) {
  CV_Assert(image.type() == CV_8UC1 && image.cols <= score_.cols && image.rows <= score_.rows);
  image_ = image;
  border_ = std::max(border, 3);
  dropped_ = 0;
  num_raw_ = 0;
  const int x_end = image.cols - border_, y_end = image.rows - border_;
  const int row_bytes = x_end - border_ + 2;
  for (int y = border_ - 1; y <= y_end; ++y) {
    std::memset(score_.ptr<uint8_t>(y) + border_ - 1, 0, static_cast<size_t>(row_bytes));
  }
}

namespace {

// True when some byte of `v` is nonzero. SSE2: one compare with zero and its sign mask; NEON
// (aarch64): the across-vector maximum.
inline bool anyNonZero(const cv::v_uint8x16& v) {
#if CV_NEON && defined(__aarch64__)
  return vmaxvq_u8(v.val) != 0;
#else
  return cv::v_signmask(v == cv::v_setzero_u8()) != 0xFFFF;
#endif
}

// Max over the 16 cyclic arcs of 9 of the minimum of `diff` over the arc. With the circle
// unrolled to e[0..23] (e[i] = diff[i % 16]) and cut into blocks [0..8], [9..17], [18..23], an
// arc starting at k lies in one block (k = 0, 9) or is a suffix of one block and a prefix of
// the next, so suffix and prefix minima give every arc: 42 minimums instead of 64 by doubling.
inline cv::v_uint8x16 arcScore(const cv::v_uint8x16* diff, cv::v_uint8x16 score) {
  auto e = [diff](int i) { return diff[i & 15]; };
  cv::v_uint8x16 suffix_a[9], prefix_b[8], suffix_b[8], prefix_c[6];
  suffix_a[8] = e(8);  // suffix_a[k] = min e[k..8]
  for (int k = 7; k >= 0; --k) suffix_a[k] = cv::v_min(e(k), suffix_a[k + 1]);
  prefix_b[0] = e(9);  // prefix_b[j] = min e[9..9 + j]
  for (int j = 1; j < 8; ++j) prefix_b[j] = cv::v_min(prefix_b[j - 1], e(9 + j));
  suffix_b[7] = e(17);  // suffix_b[j] = min e[10 + j..17]
  for (int j = 6; j >= 0; --j) suffix_b[j] = cv::v_min(e(10 + j), suffix_b[j + 1]);
  prefix_c[0] = e(18);  // prefix_c[j] = min e[18..18 + j]
  for (int j = 1; j < 6; ++j) prefix_c[j] = cv::v_min(prefix_c[j - 1], e(18 + j));
  score = cv::v_max(score, suffix_a[0]);  // the arc 0..8
  for (int k = 1; k <= 8; ++k) score = cv::v_max(score, cv::v_min(suffix_a[k], prefix_b[k - 1]));
  score = cv::v_max(score, cv::v_min(e(9), suffix_b[0]));  // the arc 9..17
  for (int k = 10; k <= 15; ++k) score = cv::v_max(score, cv::v_min(suffix_b[k - 10], prefix_c[k - 10]));
  return score;
}

// A block of 16 pixels that passed the compass tests, for the second phase of a row.
struct CompassSurvivor {
  cv::v_uint8x16 bright, dark;  // nonzero in the lanes that passed, per side
  int bx;                       // first pixel of the block
  int first_lane;               // lanes below it belong to the previous block (the row's last block)
};

// The compass tests on the 16 pixels at `p` (bx of a row), in saturating differences of the
// brightest / darkest of a pair of circle pixels: sat(max(a, b) - (c + t)) is nonzero exactly
// where a or b is brighter than c + t, sat((c - t) - min(a, b)) where one is darker than c - t.
// An arc of 9 of the 16 always covers p0 or p8 (the rest, 1..7 and 9..15, are arcs of 7); it
// also covers two neighbouring compass pixels (0-4, 4-8, 8-12 or 12-0), i.e. (p0 or p8) and
// (p4 or p12), on the same side; and, with the other four even pixels, one of each pair (0, 8),
// (2, 10), (4, 12), (6, 14). Most blocks stop after the first pair. Returns false when no lane
// can be a corner; else `bright` / `dark` are nonzero in the lanes that may be, per side.
inline bool compassTest(const uint8_t* p, const std::ptrdiff_t* circle, const cv::v_uint8x16& t,
                        cv::v_uint8x16& bright, cv::v_uint8x16& dark) {
  const cv::v_uint8x16 c = cv::v_load(p);
  const cv::v_uint8x16 c_hi = c + t, c_lo = c - t;  // saturating
  const cv::v_uint8x16 n = cv::v_load(p + circle[0]), s = cv::v_load(p + circle[8]);
  bright = cv::v_max(n, s) - c_hi;
  dark = c_lo - cv::v_min(n, s);
  if (!anyNonZero(bright | dark)) return false;
  const cv::v_uint8x16 e = cv::v_load(p + circle[4]), w = cv::v_load(p + circle[12]);
  bright = cv::v_min(bright, cv::v_max(e, w) - c_hi);
  dark = cv::v_min(dark, c_lo - cv::v_min(e, w));
  if (!anyNonZero(bright | dark)) return false;
  const cv::v_uint8x16 ne = cv::v_load(p + circle[2]), sw = cv::v_load(p + circle[10]);
  const cv::v_uint8x16 se = cv::v_load(p + circle[6]), nw = cv::v_load(p + circle[14]);
  bright = cv::v_min(bright, cv::v_min(cv::v_max(ne, sw) - c_hi, cv::v_max(se, nw) - c_hi));
  dark = cv::v_min(dark, cv::v_min(c_lo - cv::v_min(ne, sw), c_lo - cv::v_min(se, nw)));
  return anyNonZero(bright | dark);
}

}  // namespace

void FastDetector::scan(int threshold, int x0, int y0, int x1, int y1) {
  const cv::Mat& image = image_;
  const int stride = static_cast<int>(image.step[0]);
  x0 = std::max(x0, border_);
  y0 = std::max(y0, border_);
  const int x_end = std::min(x1, image.cols - border_), y_end = std::min(y1, image.rows - border_);
  threshold = std::clamp(threshold, 1, 254);

  // Pointer-sized offsets: with int ones GCC re-extended all 16 to 64 bits at every row (about a
  // tenth of the scan, as the low-threshold pass visits many short cell rows).
  std::ptrdiff_t circle[16];
  for (int k = 0; k < 16; ++k) circle[k] = std::ptrdiff_t(kCircleY[k]) * stride + kCircleX[k];
  // Unsigned byte comparisons as signed ones on values with the top bit flipped (SSE2 only has
  // signed byte compares): a > b  <=>  (a ^ 0x80) > (b ^ 0x80).
  const cv::v_uint8x16 t = cv::v_setall_u8(static_cast<uint8_t>(threshold));
  const cv::v_int8x16 sign = cv::v_setall_s8(-128);
  auto flip = [&sign](const cv::v_uint8x16& v) { return cv::v_reinterpret_as_s8(v) ^ sign; };
  const cv::v_int8x16 nine = cv::v_setall_s8(9);
  const cv::v_uint8x16 zero = cv::v_setzero_u8();
  auto record = [&](uint8_t* score_row, int x, int y, int score) {
    if (score <= threshold) return;
    score_row[x] = static_cast<uint8_t>(std::min(score, 255));
    if (num_raw_ < capacity_) raw_[num_raw_++] = FastCorner{int16_t(x), int16_t(y), uint8_t(std::min(score, 255))};
    else ++dropped_;
  };
  // A row in two phases, so that each loop keeps its values in registers (SSE2 has 16): the
  // compass tests over every block, then the count and the score on the blocks that passed.
  // Blocks of 16 pixels; the last one is moved back to end at x_end, and its lanes below
  // `first_lane` (done by the previous block) are ignored. Rows narrower than a block: scalar.
  constexpr int kMaxBlocks = 64;  // survivors buffered per pass over a row
  CompassSurvivor survivors[kMaxBlocks];
  const bool blocks = x_end - x0 >= 16;
  for (int y = y0; y < y_end; ++y) {
    const uint8_t* row = image.ptr<uint8_t>(y);
    uint8_t* score_row = score_.ptr<uint8_t>(y);
    for (int x = x0; blocks && x < x_end;) {
      int num_survivors = 0;
      for (; x + 16 <= x_end && num_survivors < kMaxBlocks; x += 16) {
        CompassSurvivor& s = survivors[num_survivors];
        if (compassTest(row + x, circle, t, s.bright, s.dark)) {
          s.bx = x;
          s.first_lane = 0;
          ++num_survivors;
        }
      }
      if (x < x_end && num_survivors < kMaxBlocks) {  // the row's last block, moved back
        CompassSurvivor& s = survivors[num_survivors];
        if (compassTest(row + x_end - 16, circle, t, s.bright, s.dark)) {
          s.bx = x_end - 16;
          s.first_lane = x - (x_end - 16);
          ++num_survivors;
        }
        x = x_end;
      }
      for (int i = 0; i < num_survivors; ++i) {
        const CompassSurvivor& s = survivors[i];
        const uint8_t* p = row + s.bx;
        const cv::v_uint8x16 c = cv::v_load(p);
        const cv::v_int8x16 hi = flip(c + t), lo = flip(c - t);
        // Second filter, the full count: an arc of 9 needs >= 9 of the 16 pixels on one side. It
        // also tells which sides can still have a corner, so only those get scored below.
        // A side no lane passed the compass tests on is not counted.
        cv::v_int8x16 maybe_bright = cv::v_setzero_s8(), maybe_dark = cv::v_setzero_s8();
        if (anyNonZero(s.bright)) {
          cv::v_int8x16 bright = cv::v_setzero_s8();
          for (int k = 0; k < 16; ++k) bright -= (flip(cv::v_load(p + circle[k])) > hi);  // true is -1
          maybe_bright = (bright >= nine) & cv::v_reinterpret_as_s8(s.bright != zero);
        }
        if (anyNonZero(s.dark)) {
          cv::v_int8x16 dark = cv::v_setzero_s8();
          for (int k = 0; k < 16; ++k) dark -= (flip(cv::v_load(p + circle[k])) < lo);
          maybe_dark = (dark >= nine) & cv::v_reinterpret_as_s8(s.dark != zero);
        }
        const bool any_bright = cv::v_check_any(maybe_bright), any_dark = cv::v_check_any(maybe_dark);
        if (!any_bright && !any_dark) continue;
        // Score in saturating u8 arithmetic: with b_k = sat(I_k - c) and e_k = sat(c - I_k), the
        // score is the max over the 16 arcs of 9 of min(b) (bright side) or min(e) (dark side); a
        // pixel is a corner exactly when its score exceeds the threshold (the segment test). Arcs
        // of 9 of 16 cannot be bright and dark at once, so a corner's score is that of the side
        // that passed the count: a side no lane can pass is skipped without changing any score.
        cv::v_uint8x16 score = cv::v_setzero_u8();
        cv::v_uint8x16 diff[16];
        if (any_bright) {
          for (int k = 0; k < 16; ++k) diff[k] = cv::v_load(p + circle[k]) - c;
          score = arcScore(diff, score);
        }
        if (any_dark) {
          for (int k = 0; k < 16; ++k) diff[k] = c - cv::v_load(p + circle[k]);
          score = arcScore(diff, score);
        }
        const cv::v_uint8x16 candidates = cv::v_reinterpret_as_u8(maybe_bright | maybe_dark);
        int mask = cv::v_signmask((score > t) & candidates) & (0xFFFF << s.first_lane);
        if (!mask) continue;
        uint8_t lane_score[16];
        cv::v_store(lane_score, score);
        while (mask) {
          const int lane = __builtin_ctz(mask);
          mask &= mask - 1;
          record(score_row, s.bx + lane, y, lane_score[lane]);
        }
      }
    }
    for (int x = blocks ? x_end : x0; x < x_end; ++x) {
      record(score_row, x, y, fastScore(row + x, stride));  // rows narrower than one block
    }
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

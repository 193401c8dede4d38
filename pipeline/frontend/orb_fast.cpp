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

// a <= b and a >= b on unsigned bytes, 0xFF where true. SSE2 has only signed byte compares, and
// OpenCV's unsigned ones flip both sides' top bits first; max(a, b) == b is two instructions.
// NEON compares unsigned bytes in one.
inline cv::v_uint8x16 atMost(const cv::v_uint8x16& a, const cv::v_uint8x16& b) {
#if CV_NEON
  return a <= b;
#else
  return cv::v_max(a, b) == b;
#endif
}
inline cv::v_uint8x16 atLeast(const cv::v_uint8x16& a, const cv::v_uint8x16& b) {
#if CV_NEON
  return a >= b;
#else
  return cv::v_min(a, b) == b;
#endif
}

// Keeps the compiler from reusing loads made before it (it may not assume memory unchanged).
inline void compilerBarrier() { asm volatile("" ::: "memory"); }

// True when some byte of `v` is nonzero. SSE2: one compare with zero and its sign mask; NEON
// (aarch64): the across-vector maximum.
inline bool anyNonZero(const cv::v_uint8x16& v) {
#if CV_NEON && defined(__aarch64__)
  return vmaxvq_u8(v.val) != 0;
#else
  return cv::v_signmask(v == cv::v_setzero_u8()) != 0xFFFF;
#endif
}

// Addresses of the 16 circle pixels of the block at `p` as base + stride x {0, 1, 2} + dx from
// three bases (rows y - 3, y, y + 3): x86-64 addressing forms each with no arithmetic and no
// table of offsets (a table of 16 offsets does not fit in registers and was reloaded per load).
struct CircleAddress {
  const uint8_t *up, *mid, *down;
  std::ptrdiff_t stride;
  CircleAddress(const uint8_t* p, std::ptrdiff_t s) : up(p - 3 * s), mid(p), down(p + 3 * s), stride(s) {}
  const uint8_t* operator()(int k) const {
    const int dy = kCircleY[k], dx = kCircleX[k];
    if (dy < -1) return up + (dy + 3) * stride + dx;   // rows y - 3, y - 2
    if (dy == -1) return up + 2 * stride + dx;
    if (dy < 3) return mid + dy * stride + dx;         // rows y .. y + 2
    return down + dx;
  }
  cv::v_uint8x16 load(int k) const { return cv::v_load((*this)(k)); }
};

// The segment test's score from the circle's raw values. With b_k = sat(I_k - c) and
// e_k = sat(c - I_k), a pixel's score is the max over the 16 arcs of 9 of min(b) (bright side)
// or min(e) (dark side). sat(x - c) grows with x, so the bright score is sat(M - c) with M the
// max over the arcs of the arc's minimum of I; sat(c - x) shrinks, so the dark score is
// sat(c - m) with m the min over the arcs of the arc's maximum. kBright picks which: `inner`
// is taken along an arc, `outer` across the arcs. No differences per pixel are needed.
//
// With the circle unrolled to e[0..23] (e[i] = I_(i % 16)) and cut into blocks [0..8], [9..17],
// [18..23], an arc starting at k lies in one block (k = 0, 9) or is a suffix of one block and a
// prefix of the next, so suffix and prefix extremes give every arc: 42 `inner` operations instead
// of 64 by doubling. The suffixes of a block are kept and the prefixes of the next one streamed;
// each block's pixels are loaded again rather than kept (a compiler barrier stops the loads being
// merged), so that no more than ~12 vectors are live: x86-64 has 16 vector registers, and with
// all 16 kept GCC spilled ~70 of the ~170 instructions to the stack.
template <bool kBright>
inline cv::v_uint8x16 arcExtreme(const CircleAddress& at) {
  auto inner = [](const cv::v_uint8x16& a, const cv::v_uint8x16& b) { return kBright ? cv::v_min(a, b) : cv::v_max(a, b); };
  auto outer = [](const cv::v_uint8x16& a, const cv::v_uint8x16& b) { return kBright ? cv::v_max(a, b) : cv::v_min(a, b); };
  auto e = [&at](int i) { return at.load(i & 15); };
  cv::v_uint8x16 suffix[9];
  suffix[8] = e(8);  // suffix[k] = inner e[k..8]
  for (int k = 7; k >= 0; --k) suffix[k] = inner(e(k), suffix[k + 1]);
  cv::v_uint8x16 best = suffix[0];  // the arc 0..8
  compilerBarrier();
  cv::v_uint8x16 prefix = e(9);  // inner e[9..k + 8] for the arc k = 1..8
  for (int k = 1; k <= 8; ++k) {
    best = outer(best, inner(suffix[k], prefix));
    if (k < 8) prefix = inner(prefix, e(9 + k));
  }
  compilerBarrier();
  suffix[7] = e(17);  // suffix[j] = inner e[10 + j..17]
  for (int j = 6; j >= 0; --j) suffix[j] = inner(e(10 + j), suffix[j + 1]);
  best = outer(best, inner(e(9), suffix[0]));  // the arc 9..17
  compilerBarrier();
  prefix = e(18);  // inner e[18..k + 8] for the arc k = 10..15
  for (int k = 10; k <= 15; ++k) {
    best = outer(best, inner(suffix[k - 10], prefix));
    if (k < 15) prefix = inner(prefix, e(k + 9));
  }
  return best;
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
inline bool compassTest(const CircleAddress& at, const cv::v_uint8x16& t,
                        cv::v_uint8x16& bright, cv::v_uint8x16& dark) {
  const cv::v_uint8x16 c = cv::v_load(at.mid);
  const cv::v_uint8x16 c_hi = c + t, c_lo = c - t;  // saturating
  const cv::v_uint8x16 n = at.load(0), s = at.load(8);
  bright = cv::v_max(n, s) - c_hi;
  dark = c_lo - cv::v_min(n, s);
  if (!anyNonZero(bright | dark)) return false;
  const cv::v_uint8x16 e = at.load(4), w = at.load(12);
  bright = cv::v_min(bright, cv::v_max(e, w) - c_hi);
  dark = cv::v_min(dark, c_lo - cv::v_min(e, w));
  if (!anyNonZero(bright | dark)) return false;
  const cv::v_uint8x16 ne = at.load(2), sw = at.load(10);
  const cv::v_uint8x16 se = at.load(6), nw = at.load(14);
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

  const std::ptrdiff_t row_step = stride;
  const cv::v_uint8x16 t = cv::v_setall_u8(static_cast<uint8_t>(threshold));
  const cv::v_uint8x16 eight = cv::v_setall_u8(8);
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
      // The tests write into registers; only survivors are stored (storing every block's result
      // into the buffer cost ~4 instructions a block).
      cv::v_uint8x16 bright, dark;
      auto keep = [&](int bx, int first_lane) {
        survivors[num_survivors++] = CompassSurvivor{bright, dark, bx, first_lane};
      };
      for (; x + 16 <= x_end && num_survivors < kMaxBlocks; x += 16) {
        if (compassTest(CircleAddress(row + x, row_step), t, bright, dark)) keep(x, 0);
      }
      if (x < x_end && num_survivors < kMaxBlocks) {  // the row's last block, moved back
        if (compassTest(CircleAddress(row + x_end - 16, row_step), t, bright, dark)) keep(x_end - 16, x - (x_end - 16));
        x = x_end;
      }
      for (int i = 0; i < num_survivors; ++i) {
        const CompassSurvivor& s = survivors[i];
        const CircleAddress at(row + s.bx, row_step);
        const cv::v_uint8x16 c = cv::v_load(at.mid);
        const cv::v_uint8x16 c_hi = c + t, c_lo = c - t;  // saturating
        // Second filter, the full count: an arc of 9 needs >= 9 of the 16 pixels on one side, i.e.
        // at most 7 not on it. It also tells which sides can still have a corner, so only those
        // get scored below; a side no lane passed the compass tests on is not counted.
        cv::v_int8x16 maybe_bright = cv::v_setzero_s8(), maybe_dark = cv::v_setzero_s8();
        if (anyNonZero(s.bright)) {
          cv::v_uint8x16 not_bright = zero;
#pragma GCC unroll 16
          for (int k = 0; k < 16; ++k) not_bright = cv::v_sub_wrap(not_bright, atMost(at.load(k), c_hi));  // true: 0xFF = -1
          maybe_bright = cv::v_reinterpret_as_s8((not_bright < eight) & (s.bright != zero));
        }
        if (anyNonZero(s.dark)) {
          cv::v_uint8x16 not_dark = zero;
#pragma GCC unroll 16
          for (int k = 0; k < 16; ++k) not_dark = cv::v_sub_wrap(not_dark, atLeast(at.load(k), c_lo));
          maybe_dark = cv::v_reinterpret_as_s8((not_dark < eight) & (s.dark != zero));
        }
        compilerBarrier();  // the score loads the pixels again rather than keep 16 of them (spills)
        const bool any_bright = cv::v_check_any(maybe_bright), any_dark = cv::v_check_any(maybe_dark);
        if (!any_bright && !any_dark) continue;
        // Score in saturating u8 arithmetic: with b_k = sat(I_k - c) and e_k = sat(c - I_k), the
        // score is the max over the 16 arcs of 9 of min(b) (bright side) or min(e) (dark side); a
        // pixel is a corner exactly when its score exceeds the threshold (the segment test). Arcs
        // of 9 of 16 cannot be bright and dark at once, so a corner's score is that of the side
        // that passed the count: a side no lane can pass is skipped without changing any score.
        cv::v_uint8x16 score = cv::v_setzero_u8();
        if (any_bright) score = arcExtreme<true>(at) - c;  // saturating
        if (any_dark) score = cv::v_max(score, c - arcExtreme<false>(at));
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

#include "pipeline/frontend/image_pyramid.h"

#include <cmath>
#include <cstring>
#include <utility>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

namespace plumb {

ImagePyramid::ImagePyramid(int width, int height, int num_levels, float scale_factor)
    : num_levels_(num_levels < 1 ? 1 : (num_levels > kPyramidLevels ? kPyramidLevels : num_levels)) {
  std::array<cv::Size, kPyramidLevels> sizes;
  int total_rows = 0;
  for (int i = 0; i < num_levels_; ++i) {
    scales_[i] = std::pow(scale_factor, static_cast<float>(i));
    sizes[i] = cv::Size(static_cast<int>(std::lround(width / scales_[i])),
                        static_cast<int>(std::lround(height / scales_[i])));
    total_rows += sizes[i].height;
  }
  row_filtered_.create(1, width + 6, CV_8UC1);  // one padded row
  high_row_.create(1, width + 8, CV_16SC1);  // + padding: see downsample()
  low_row_.create(1, width + 8, CV_16SC1);
  high_row_.setTo(0);
  low_row_.setTo(0);
  for (int i = 1; i < num_levels_; ++i) {
    x_tap_start_[i] = static_cast<int>(x_taps_.size());
    appendTaps(sizes[i - 1].width, sizes[i].width, x_taps_);
    y_tap_start_[i] = static_cast<int>(y_taps_.size());
    appendTaps(sizes[i - 1].height, sizes[i].height, y_taps_);
  }
  for (const Tap& t : x_taps_) {
    // downsample() reads the pair (index0, index0 + 1): index1 may differ only with weight 0.
    CV_Assert(t.index1 == t.index0 + 1 || t.weight == 0);
    x_weight_pairs_.push_back(((1 << kWeightBits) - t.weight) | (t.weight << 16));
  }
  buffer_.create(total_rows, width, CV_8UC1);
  blurred_buffer_.create(total_rows, width, CV_8UC1);
  buffer_.setTo(0);
  blurred_buffer_.setTo(0);
  int row = 0;
  for (int i = 0; i < num_levels_; ++i) {
    const cv::Rect roi(0, row, sizes[i].width, sizes[i].height);
    levels_[i] = buffer_(roi);
    blurred_levels_[i] = blurred_buffer_(roi);
    row += sizes[i].height;
  }
}

void ImagePyramid::build(const cv::Mat& grey) {
  grey.copyTo(levels_[0]);  // levels_[0] has the right size: copyTo writes in place
  for (int i = 1; i < num_levels_; ++i) {
    // Resize from the previous level (as ORB-SLAM does): cheap, and the 1.2 step keeps
    // bilinear aliasing small.
    downsample(i);
  }
  // The smoothing rotated BRIEF is defined on (blur() below).
  for (int i = 0; i < num_levels_; ++i) blur(levels_[i], blurred_levels_[i]);
}

void ImagePyramid::appendTaps(int src_size, int dst_size, std::vector<Tap>& taps) {
  const double step = static_cast<double>(src_size) / dst_size;
  for (int d = 0; d < dst_size; ++d) {
    const double f = (d + 0.5) * step - 0.5;  // source coordinate of the destination pixel centre
    int index = static_cast<int>(std::floor(f));
    double fraction = f - index;
    if (index < 0) index = 0, fraction = 0;
    if (index >= src_size - 1) index = src_size - 1, fraction = 0;
    const int weight = static_cast<int>(std::lround(fraction * (1 << kWeightBits)));
    taps.push_back({index, index + 1 < src_size ? index + 1 : index, weight});
  }
}

void ImagePyramid::downsample(int level) {
  const cv::Mat& src = levels_[level - 1];
  cv::Mat& dst = levels_[level];
  const Tap* x_taps = x_taps_.data() + x_tap_start_[level];
  const int32_t* x_weights = x_weight_pairs_.data() + x_tap_start_[level];
  const Tap* y_taps = y_taps_.data() + y_tap_start_[level];
  const int one = 1 << kWeightBits;
  constexpr int kRound = 1 << (2 * kWeightBits - 1);
  // Each output pixel is the exact integer sum_ij p_ij * wy_i * wx_j (<= 255 * 2048^2, fits an
  // int32), rounded once at the end, so the order of the passes and the split below do not
  // change a single value.
  // Vertical first: v = p0 * wy0 + p1 * wy1 (< 2^19) along contiguous source rows, 8 pixels per
  // multiply-add of interleaved (row0, row1) 16-bit pairs against (wy0, wy1). v is kept as
  // v = 1024 * high + low (high < 512, low < 1024) so the horizontal pass can also use 16-bit
  // multiply-adds: v0 * wx0 + v1 * wx1 = 1024 * (high0 * wx0 + high1 * wx1) + (low0 * wx0 + low1 * wx1),
  // where each (x0, x0 + 1) pair is one 32-bit read.
  int16_t* high = high_row_.ptr<int16_t>(0);
  int16_t* low = low_row_.ptr<int16_t>(0);
  const cv::v_int32x4 low_mask = cv::v_setall_s32(1023), round = cv::v_setall_s32(kRound);
  auto pairAt = [](const int16_t* row, int x) {  // (row[x], row[x + 1]) as one 32-bit lane
    int32_t pair;
    std::memcpy(&pair, row + x, sizeof(pair));
    return pair;
  };
  for (int y = 0; y < dst.rows; ++y) {
    const Tap& ty = y_taps[y];
    const uint8_t* s0 = src.ptr<uint8_t>(ty.index0);
    const uint8_t* s1 = src.ptr<uint8_t>(ty.index1);
    const int w1 = ty.weight, w0 = one - w1;
    const cv::v_int16x8 weights = cv::v_reinterpret_as_s16(cv::v_setall_s32(w0 | (w1 << 16)));
    int x = 0;
    for (; x + 8 <= src.cols; x += 8) {
      const cv::v_int16x8 a = cv::v_reinterpret_as_s16(cv::v_load_expand(s0 + x));
      const cv::v_int16x8 b = cv::v_reinterpret_as_s16(cv::v_load_expand(s1 + x));
      cv::v_int16x8 lo, hi;
      cv::v_zip(a, b, lo, hi);  // (a0, b0, a1, b1, ...)
      const cv::v_int32x4 v_lo = cv::v_dotprod(lo, weights), v_hi = cv::v_dotprod(hi, weights);
      cv::v_store(high + x, cv::v_pack(v_lo >> 10, v_hi >> 10));
      cv::v_store(low + x, cv::v_pack(v_lo & low_mask, v_hi & low_mask));
    }
    for (; x < src.cols; ++x) {
      const int v = s0[x] * w0 + s1[x] * w1;
      high[x] = static_cast<int16_t>(v >> 10);
      low[x] = static_cast<int16_t>(v & 1023);
    }
    // Horizontal. The clamped last tap reads the pair (x0, x0 + 1) with weights (2048, 0): the
    // padding element past the row only ever meets a zero weight.
    uint8_t* d = dst.ptr<uint8_t>(y);
    int xd = 0;
    for (; xd + 8 <= dst.cols; xd += 8) {
      cv::v_int32x4 sums[2];
      for (int g = 0; g < 2; ++g) {
        const Tap* t = x_taps + xd + 4 * g;
        const cv::v_int16x8 high_pairs = cv::v_reinterpret_as_s16(cv::v_int32x4(
            pairAt(high, t[0].index0), pairAt(high, t[1].index0), pairAt(high, t[2].index0), pairAt(high, t[3].index0)));
        const cv::v_int16x8 low_pairs = cv::v_reinterpret_as_s16(cv::v_int32x4(
            pairAt(low, t[0].index0), pairAt(low, t[1].index0), pairAt(low, t[2].index0), pairAt(low, t[3].index0)));
        const cv::v_int16x8 w = cv::v_reinterpret_as_s16(cv::v_load(x_weights + xd + 4 * g));
        sums[g] = ((cv::v_dotprod(high_pairs, w) << 10) + cv::v_dotprod(low_pairs, w) + round) >> (2 * kWeightBits);
      }
      cv::v_pack_u_store(d + xd, cv::v_pack(sums[0], sums[1]));
    }
    for (; xd < dst.cols; ++xd) {
      const Tap& t = x_taps[xd];
      const int v0 = high[t.index0] * 1024 + low[t.index0], v1 = high[t.index1] * 1024 + low[t.index1];
      d[xd] = static_cast<uint8_t>((v0 * one + (v1 - v0) * t.weight + kRound) >> (2 * kWeightBits));
    }
  }
}

// The smoothing rotated BRIEF compares on: a 7-tap filter built from rounding byte averages,
// avg(avg(c, p1), avg(p2, avg(p1, p3))) with p_i = avg(x - i, x + i), i.e. the triangle
// (1, 2, 3, 4, 3, 2, 1) / 16 before rounding (variance 2.5 px^2, sigma 1.58; the 7-tap Gaussian of
// sigma 2 it replaces has an effective sigma of 1.64 after truncation). Six byte averages per 16
// pixels and pass, where the 16-bit fixed-point Gaussian took ~7 instructions a pixel (a fifth of
// ORB). Each average rounds up (pavgb / urhadd), which shifts the whole image by at most a grey
// level and a half: BRIEF's pixel comparisons do not see a common offset. Vertical pass into a
// padded byte row, then horizontal; reflected borders (BORDER_REFLECT_101).
namespace {

// The filter on seven bytes / vectors at offsets -3..3 (a[0] .. a[6]).
template <typename T, typename Avg>
inline T triangleTree(const T& m3, const T& m2, const T& m1, const T& c, const T& p1, const T& p2, const T& p3,
                      Avg avg) {
  const T a1 = avg(m1, p1), a2 = avg(m2, p2), a3 = avg(m3, p3);
  return avg(avg(c, a1), avg(a2, avg(a1, a3)));
}

inline uint8_t averageUp(uint8_t a, uint8_t b) { return static_cast<uint8_t>((a + b + 1) >> 1); }

// (a + b + 1) >> 1 per byte: one instruction on both targets (OpenCV 4.6's universal intrinsics
// have no byte average, so the two native ones are named here).
inline cv::v_uint8x16 averageUp(const cv::v_uint8x16& a, const cv::v_uint8x16& b) {
#if CV_SSE2
  return cv::v_uint8x16(_mm_avg_epu8(a.val, b.val));
#elif CV_NEON
  return cv::v_uint8x16(vrhaddq_u8(a.val, b.val));
#else
  uint8_t x[16], y[16];
  cv::v_store(x, a);
  cv::v_store(y, b);
  for (int i = 0; i < 16; ++i) x[i] = averageUp(x[i], y[i]);
  return cv::v_load(x);
#endif
}

}  // namespace

uint8_t ImagePyramid::blurTap(uint8_t m3, uint8_t m2, uint8_t m1, uint8_t c, uint8_t p1, uint8_t p2, uint8_t p3) {
  return triangleTree(m3, m2, m1, c, p1, p2, p3, [](uint8_t a, uint8_t b) { return averageUp(a, b); });
}

void ImagePyramid::blur(const cv::Mat& src, cv::Mat& dst) {
  const int w = src.cols, h = src.rows;
  auto reflect = [](int i, int n) { return i < 0 ? -i : (i >= n ? 2 * n - 2 - i : i); };  // REFLECT_101
  auto vavg = [](const cv::v_uint8x16& a, const cv::v_uint8x16& b) { return averageUp(a, b); };
  uint8_t* t = row_filtered_.ptr<uint8_t>(0) + 3;  // t[-3 .. w+2] valid after padding
  for (int y = 0; y < h; ++y) {
    const uint8_t* r[7];
    for (int i = 0; i < 7; ++i) r[i] = src.ptr<uint8_t>(reflect(y + i - 3, h));
    int x = 0;
    for (; x + 16 <= w; x += 16) {
      cv::v_store(t + x, triangleTree(cv::v_load(r[0] + x), cv::v_load(r[1] + x), cv::v_load(r[2] + x),
                                      cv::v_load(r[3] + x), cv::v_load(r[4] + x), cv::v_load(r[5] + x),
                                      cv::v_load(r[6] + x), vavg));
    }
    for (; x < w; ++x) t[x] = blurTap(r[0][x], r[1][x], r[2][x], r[3][x], r[4][x], r[5][x], r[6][x]);
    for (int i = 1; i <= 3; ++i) {
      t[-i] = t[reflect(-i, w)];
      t[w - 1 + i] = t[reflect(w - 1 + i, w)];
    }
    uint8_t* d = dst.ptr<uint8_t>(y);
    x = 0;
    for (; x + 16 <= w; x += 16) {
      const uint8_t* q = t + x;
      cv::v_store(d + x, triangleTree(cv::v_load(q - 3), cv::v_load(q - 2), cv::v_load(q - 1), cv::v_load(q),
                                      cv::v_load(q + 1), cv::v_load(q + 2), cv::v_load(q + 3), vavg));
    }
    for (; x < w; ++x) {
      const uint8_t* q = t + x;
      d[x] = blurTap(q[-3], q[-2], q[-1], q[0], q[1], q[2], q[3]);
    }
  }
}

}  // namespace plumb

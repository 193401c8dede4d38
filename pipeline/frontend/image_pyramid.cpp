#include "pipeline/frontend/image_pyramid.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

// Byte shuffles for downsample(): SSSE3's pshufb (x86-64, chosen at run time: the baseline is
// SSE2) or NEON's tbl (every aarch64 CPU). Elsewhere the portable gather path alone.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <tmmintrin.h>
#define PLUMB_PYRAMID_SHUFFLE 1
#define PLUMB_PYRAMID_SHUFFLE_TARGET __attribute__((target("ssse3")))
#elif defined(__aarch64__)
#include <arm_neon.h>
#define PLUMB_PYRAMID_SHUFFLE 1
#define PLUMB_PYRAMID_SHUFFLE_TARGET
#else
#define PLUMB_PYRAMID_SHUFFLE 0
#endif

namespace plumb {
#if PLUMB_PYRAMID_SHUFFLE
namespace {

// 16 bytes at `row`, permuted: byte i of the result is byte shuffle[i] of the input (< 16).
PLUMB_PYRAMID_SHUFFLE_TARGET inline cv::v_int16x8 shuffleBytes(const int16_t* row, const uint8_t* shuffle) {
#if defined(__x86_64__)
  const __m128i bytes = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row));
  return cv::v_int16x8(_mm_shuffle_epi8(bytes, _mm_loadu_si128(reinterpret_cast<const __m128i*>(shuffle))));
#else
  const uint8x16_t bytes = vld1q_u8(reinterpret_cast<const uint8_t*>(row));
  return cv::v_int16x8(vreinterpretq_s16_u8(vqtbl1q_u8(bytes, vld1q_u8(shuffle))));
#endif
}

bool cpuHasShuffle() {
#if defined(__x86_64__)
  static const bool has = __builtin_cpu_supports("ssse3");
  return has;
#else
  return true;
#endif
}

}  // namespace
#endif

namespace {

// Pieces of the blur both of its paths share: the columns left to scalar code after the vector
// blocks, and the mirrored columns past an image edge. T: the vertical result's element type.
int reflect101(int i, int n) { return i < 0 ? -i : (i >= n ? 2 * n - 2 - i : i); }

template <class T>
void blurVerticalScalar(const uint8_t* const* r, const int* k, int from, int to, T* t) {
  for (int x = from; x < to; ++x) {
    int acc = 0;
    for (int i = 0; i < 7; ++i) acc += k[i] * r[i][x];
    t[x] = static_cast<T>((acc + 128) >> 8);
  }
}

template <class T>
void mirrorEdges(T* t, int w, int x0, int x1) {  // the horizontal pass reads t[x0 - 3 .. x1 + 2]
  for (int i = 1; i <= 3; ++i) {
    if (x0 < 3) t[-i] = t[reflect101(-i, w)];
    if (x1 + 3 > w) t[w - 1 + i] = t[reflect101(w - 1 + i, w)];
  }
}

template <class T>
void blurHorizontalScalar(const T* t, const int* k, int from, int to, uint8_t* d) {
  for (int x = from; x < to; ++x) {
    int acc = 0;
    for (int i = 0; i < 7; ++i) acc += k[i] * t[x + i - 3];
    d[x] = static_cast<uint8_t>((acc + 128) >> 8);
  }
}

}  // namespace

#if PLUMB_PYRAMID_SHUFFLE && defined(__x86_64__)
namespace {

// The blur of blur() on rows [y0, y1), columns [x0, x1) with SSSE3's pmaddubsw (unsigned bytes
// times signed bytes, adjacent products summed into 16 bits): the two rows (or columns) that
// share a weight are interleaved and multiplied by (k, k), the centre by (k3, 0). Every pair sum
// is <= 255 * 2 * 127 (no saturation; the weights are < 128) and their total <= 255 * 256 wraps
// nowhere in unsigned 16 bits, so the integers are those of the portable path. The vertical
// result, (sum + 128) >> 8 <= 255, is kept in a byte row, so the horizontal pass multiplies bytes
// too: 16 pixels per step in both passes instead of 8 in the horizontal one.
struct ByteWeights {
  __m128i pair[3], centre, round;
  explicit ByteWeights(const std::array<int, 7>& k)
      : pair{_mm_set1_epi16(int16_t(k[0] | k[0] << 8)), _mm_set1_epi16(int16_t(k[1] | k[1] << 8)),
             _mm_set1_epi16(int16_t(k[2] | k[2] << 8))},
        centre(_mm_set1_epi16(int16_t(k[3]))), round(_mm_set1_epi16(128)) {}
};

#define PLUMB_BYTE_BLUR_INLINE PLUMB_PYRAMID_SHUFFLE_TARGET inline __attribute__((always_inline))

// 16 outputs (wide) or 8 (in the low half) from the 7 source rows, or shifted columns, at
// p[0], p[step], ..., p[6 * step]; stored at d.
template <bool kWide>
PLUMB_BYTE_BLUR_INLINE void blurBytes(const uint8_t* const* rows, std::ptrdiff_t offset, const ByteWeights& w, uint8_t* d) {
  const __m128i zero = _mm_setzero_si128();
  __m128i v[7];
  for (int i = 0; i < 7; ++i) {
    v[i] = kWide ? _mm_loadu_si128(reinterpret_cast<const __m128i*>(rows[i] + offset))
                 : _mm_loadl_epi64(reinterpret_cast<const __m128i*>(rows[i] + offset));
  }
  __m128i lo = _mm_maddubs_epi16(_mm_unpacklo_epi8(v[3], zero), w.centre);
  for (int i = 0; i < 3; ++i) lo = _mm_add_epi16(lo, _mm_maddubs_epi16(_mm_unpacklo_epi8(v[i], v[6 - i]), w.pair[i]));
  lo = _mm_srli_epi16(_mm_add_epi16(lo, w.round), 8);
  if (kWide) {
    __m128i hi = _mm_maddubs_epi16(_mm_unpackhi_epi8(v[3], zero), w.centre);
    for (int i = 0; i < 3; ++i) hi = _mm_add_epi16(hi, _mm_maddubs_epi16(_mm_unpackhi_epi8(v[i], v[6 - i]), w.pair[i]));
    hi = _mm_srli_epi16(_mm_add_epi16(hi, w.round), 8);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(d), _mm_packus_epi16(lo, hi));
  } else {
    _mm_storel_epi64(reinterpret_cast<__m128i*>(d), _mm_packus_epi16(lo, lo));
  }
}

// Blurs [begin, end) from `rows` (offset by the column) into d: blocks of 16, then a last block
// of 8 or 16 moved back to end at `end` (recomputing a few outputs with the same values; 8 when
// at most 8 columns are left: about half the work), or one or two blocks of 8 when the range is
// 8..15 wide; returns the first column left for a scalar tail.
PLUMB_BYTE_BLUR_INLINE int blurBlocks(const uint8_t* const* rows, int begin, int end, const ByteWeights& w, uint8_t* d) {
  if (end - begin >= 16) {
    int x = begin;
    for (; x + 16 <= end; x += 16) blurBytes<true>(rows, x, w, d + x);
    if (x + 8 >= end) {
      if (x < end) blurBytes<false>(rows, end - 8, w, d + end - 8);
    } else {
      blurBytes<true>(rows, end - 16, w, d + end - 16);
    }
    return end;
  }
  if (end - begin >= 8) {
    blurBytes<false>(rows, begin, w, d + begin);
    blurBytes<false>(rows, end - 8, w, d + end - 8);
    return end;
  }
  return begin;
}

// The horizontal pass's weights for blurRowEvenOdd(): the adjacent taps (k0, k1), (k2, k3),
// (k4, k5), (k6, 0) as byte pairs.
struct AdjacentPairWeights {
  __m128i pair[4];
  explicit AdjacentPairWeights(const std::array<int, 7>& k)
      : pair{_mm_set1_epi16(int16_t(k[0] | k[1] << 8)), _mm_set1_epi16(int16_t(k[2] | k[3] << 8)),
             _mm_set1_epi16(int16_t(k[4] | k[5] << 8)), _mm_set1_epi16(int16_t(k[6]))} {}
};

// 16 horizontal outputs at d[0..15] from the byte row t (read t[-3 .. 19]) without any byte
// interleaving: pmaddubsw on a load at t - 3 multiplies the adjacent pairs (t[2j - 3], t[2j - 2])
// by (k0, k1), the first two taps of even output 2j; loads at t - 1, t + 1 and t + 3 give its
// other taps, and the same four loads one byte later those of odd output 2j + 1. Each pair sum
// is <= 255 * 103 (no saturation) and the total is the portable path's integer sum. The even
// results go to the low byte of each 16-bit lane, the odd ones to the high byte: 8 loads and 8
// multiply-adds for 16 outputs, where interleaving the shifted rows took 7 loads, 14 unpacks and
// 8 multiply-adds.
PLUMB_BYTE_BLUR_INLINE void blurRowEvenOdd(const uint8_t* t, const AdjacentPairWeights& w, __m128i round,
                                           uint8_t* d) {
  auto at = [t](int offset) { return _mm_loadu_si128(reinterpret_cast<const __m128i*>(t + offset)); };
  __m128i even = _mm_add_epi16(_mm_maddubs_epi16(at(-3), w.pair[0]), _mm_maddubs_epi16(at(-1), w.pair[1]));
  even = _mm_add_epi16(even, _mm_add_epi16(_mm_maddubs_epi16(at(1), w.pair[2]), _mm_maddubs_epi16(at(3), w.pair[3])));
  __m128i odd = _mm_add_epi16(_mm_maddubs_epi16(at(-2), w.pair[0]), _mm_maddubs_epi16(at(0), w.pair[1]));
  odd = _mm_add_epi16(odd, _mm_add_epi16(_mm_maddubs_epi16(at(2), w.pair[2]), _mm_maddubs_epi16(at(4), w.pair[3])));
  even = _mm_srli_epi16(_mm_add_epi16(even, round), 8);
  odd = _mm_srli_epi16(_mm_add_epi16(odd, round), 8);
  _mm_storeu_si128(reinterpret_cast<__m128i*>(d), _mm_or_si128(even, _mm_slli_epi16(odd, 8)));
}

PLUMB_PYRAMID_SHUFFLE_TARGET void blurByteMultiplyAdd(const cv::Mat& src, cv::Mat& dst, int y0, int y1,
                                                      const ImagePyramid::Span* spans, int num_spans,
                                                      const std::array<int, 7>& kernel, uint8_t* t) {
  // t: the byte row, valid on [-3, w + 3) after the edge mirroring below (t[w + 3], read by the
  // last 16-wide horizontal block with weight 0, is padding). The spans are inside the image.
  const int w = src.cols, h = src.rows;
  const ByteWeights weights(kernel);
  const AdjacentPairWeights adjacent(kernel);
  const uint8_t* columns[7];  // the horizontal pass: t shifted by -3 .. 3
  for (int i = 0; i < 7; ++i) columns[i] = t + i - 3;
  for (int y = y0; y < y1; ++y) {
    const uint8_t* r[7];
    for (int i = 0; i < 7; ++i) r[i] = src.ptr<uint8_t>(reflect101(y + i - 3, h));
    uint8_t* d = dst.ptr<uint8_t>(y);
    for (const ImagePyramid::Span* span = spans; span != spans + num_spans; ++span) {
      const int x0 = span->x0, x1 = span->x1;
      const int vx0 = std::max(x0 - 3, 0), vx1 = std::min(x1 + 3, w);
      blurVerticalScalar(r, kernel.data(), blurBlocks(r, vx0, vx1, weights, t), vx1, t);
      mirrorEdges(t, w, x0, x1);
      if (x1 - x0 >= 16) {  // blocks of 16, the last one moved back to end at x1
        for (int x = x0; x < x1;) {
          const int bx = std::min(x, x1 - 16);
          blurRowEvenOdd(t + bx, adjacent, weights.round, d + bx);
          x = bx + 16;
        }
        continue;
      }
      blurHorizontalScalar(t, kernel.data(), blurBlocks(columns, x0, x1, weights, d), x1, d);
    }
  }
}

}  // namespace
#endif

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
  row_filtered_.create(1, width + 6, CV_16UC1);  // one padded row
  row_filtered_bytes_.create(1, width + 7, CV_8UC1);  // 3 px each side, 1 of padding (blurByteMultiplyAdd)
  row_filtered_bytes_.setTo(0);
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
  for (int i = 1; i < num_levels_; ++i) {
    group_start_[i] = static_cast<int>(group_base_.size());
    shuffle_ok_[i] = true;
    const Tap* taps = x_taps_.data() + x_tap_start_[i];
    for (int g = 0; g < 2 * (sizes[i].width / 8); ++g) {  // the vector loop's blocks of 8
      const int base = taps[4 * g].index0;
      group_base_.push_back(base);
      for (int j = 0; j < 4; ++j) {
        const int offset = taps[4 * g + j].index0 - base;  // element pair (offset, offset + 1)
        if (offset < 0 || offset > 6) shuffle_ok_[i] = false;
        for (int b = 0; b < 4; ++b) group_shuffle_.push_back(static_cast<uint8_t>(std::clamp(2 * offset + b, 0, 15)));
      }
    }
  }
  const cv::Mat kernel = cv::getGaussianKernel(7, 2.0, CV_64F);
  int sum = 0;
  for (int k = 0; k < 7; ++k) sum += kernel_[k] = static_cast<int>(std::lround(kernel.at<double>(k) * 256));
  kernel_[3] += 256 - sum;  // exact unit gain
  // blur() relies on the symmetry (rounding symmetric weights keeps them symmetric).
  CV_Assert(kernel_[0] == kernel_[6] && kernel_[1] == kernel_[5] && kernel_[2] == kernel_[4]);
  // The byte path where the CPU has it; its signed-byte weights need every tap < 128 (sigma 2:
  // 18, 34, 49, 54, 49, 34, 18).
  CV_Assert(*std::max_element(kernel_.begin(), kernel_.end()) < 128);
  setBlurPath(BlurPath::kByteMultiplyAdd);
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
  buildLevels(grey);
  // 7x7, sigma 2: the smoothing rotated BRIEF is defined on.
  for (int i = 0; i < num_levels_; ++i) blurRect(i, 0, 0, levels_[i].cols, levels_[i].rows);
}

void ImagePyramid::buildLevels(const cv::Mat& grey) {
  if (grey.data != levels_[0].data) grey.copyTo(levels_[0]);  // the right size: copyTo writes in place
  for (int i = 1; i < num_levels_; ++i) {
    // Resize from the previous level (as ORB-SLAM does): cheap, and the 1.2 step keeps
    // bilinear aliasing small.
    downsample(i);
  }
}

void ImagePyramid::blurRect(int level, int x0, int y0, int x1, int y1) {
  const cv::Mat& src = levels_[level];
  const Span span{std::max(x0, 0), std::min(x1, src.cols)};
  y0 = std::max(y0, 0), y1 = std::min(y1, src.rows);
  if (span.x0 >= span.x1 || y0 >= y1) return;
  blur(src, blurred_levels_[level], y0, y1, &span, 1);
}

void ImagePyramid::blurRowSpans(int level, int y0, int y1, const Span* spans, int num_spans) {
  const cv::Mat& src = levels_[level];
  y0 = std::max(y0, 0), y1 = std::min(y1, src.rows);
  if (y0 >= y1) return;
  for (int i = 0; i < num_spans; ++i) {
    CV_DbgAssert(spans[i].x0 >= 0 && spans[i].x0 < spans[i].x1 && spans[i].x1 <= src.cols);
  }
  blur(src, blurred_levels_[level], y0, y1, spans, num_spans);
}

#if PLUMB_PYRAMID_SHUFFLE
namespace {

// The horizontal pass of downsample() on whole blocks of 8 outputs, gathering the (x0, x0 + 1)
// pairs by byte shuffles; the same integer arithmetic, so the same bytes. Returns the first
// output column it did not write.
// The 4 outputs of group g. Called through a macro, not a lambda: a lambda does not carry the
// SSSE3 target, and GCC then calls shuffleBytes() instead of inlining it.
PLUMB_PYRAMID_SHUFFLE_TARGET inline __attribute__((always_inline)) cv::v_int32x4 shuffledQuad(
    const int16_t* high, const int16_t* low, const int32_t* bases, const uint8_t* shuffles, const int32_t* weights,
    int g) {
  const cv::v_int16x8 high_pairs = shuffleBytes(high + bases[g], shuffles + 16 * g);
  const cv::v_int16x8 low_pairs = shuffleBytes(low + bases[g], shuffles + 16 * g);
  const cv::v_int16x8 w = cv::v_reinterpret_as_s16(cv::v_load(weights + 4 * g));
  return ((cv::v_dotprod(high_pairs, w) << 10) + cv::v_dotprod(low_pairs, w) + cv::v_setall_s32(1 << 21)) >> 22;
}

PLUMB_PYRAMID_SHUFFLE_TARGET int horizontalShuffled(const int16_t* high, const int16_t* low, const int32_t* bases,
                                                    const uint8_t* shuffles, const int32_t* weights, int cols,
                                                    uint8_t* d) {
  // 16 outputs (4 groups) a step, one pack to bytes and one store; the group tables are walked by
  // pointer so that the loop computes no indices. Then one block of 8.
#define PLUMB_QUAD(g) shuffledQuad(high, low, bases, shuffles, weights, g)
  int xd = 0;
  for (; xd + 16 <= cols; xd += 16, bases += 4, shuffles += 64, weights += 16) {
    cv::v_store(d + xd, cv::v_pack_u(cv::v_pack(PLUMB_QUAD(0), PLUMB_QUAD(1)), cv::v_pack(PLUMB_QUAD(2), PLUMB_QUAD(3))));
  }
  if (xd + 8 <= cols) {
    cv::v_pack_u_store(d + xd, cv::v_pack(PLUMB_QUAD(0), PLUMB_QUAD(1)));
    xd += 8;
  }
#undef PLUMB_QUAD
  return xd;
}

}  // namespace
#endif

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
    // 16 pixels a step: the two rows' bytes are interleaved before widening (one zip of bytes
    // instead of one per 8 pixels of 16-bit lanes), then the same multiply-adds.
    for (; x + 16 <= src.cols; x += 16) {
      cv::v_uint8x16 ab_lo, ab_hi;
      cv::v_zip(cv::v_load(s0 + x), cv::v_load(s1 + x), ab_lo, ab_hi);  // (a0, b0, a1, b1, ...)
      cv::v_uint16x8 p[4];
      cv::v_expand(ab_lo, p[0], p[1]);
      cv::v_expand(ab_hi, p[2], p[3]);
      cv::v_int32x4 v[4];
      for (int i = 0; i < 4; ++i) v[i] = cv::v_dotprod(cv::v_reinterpret_as_s16(p[i]), weights);
      cv::v_store(high + x, cv::v_pack(v[0] >> 10, v[1] >> 10));
      cv::v_store(high + x + 8, cv::v_pack(v[2] >> 10, v[3] >> 10));
      cv::v_store(low + x, cv::v_pack(v[0] & low_mask, v[1] & low_mask));
      cv::v_store(low + x + 8, cv::v_pack(v[2] & low_mask, v[3] & low_mask));
    }
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
#if PLUMB_PYRAMID_SHUFFLE
    if (shuffle_ok_[level] && cpuHasShuffle()) {
      xd = horizontalShuffled(high, low, group_base_.data() + group_start_[level],
                              group_shuffle_.data() + 16 * group_start_[level], x_weights, dst.cols, d);
    }
#endif
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

bool ImagePyramid::setBlurPath(BlurPath path) {
  if (path == BlurPath::kByteMultiplyAdd) {
#if PLUMB_PYRAMID_SHUFFLE && defined(__x86_64__)
    if (!cpuHasShuffle()) return false;  // pmaddubsw is SSSE3, like pshufb
#else
    return false;
#endif
  }
  blur_path_ = path;
  return true;
}

void ImagePyramid::blur(const cv::Mat& src, cv::Mat& dst, int y0, int y1, const Span* spans, int num_spans) {
#if PLUMB_PYRAMID_SHUFFLE && defined(__x86_64__)
  if (blur_path_ == BlurPath::kByteMultiplyAdd) {
    blurByteMultiplyAdd(src, dst, y0, y1, spans, num_spans, kernel_, row_filtered_bytes_.ptr<uint8_t>(0) + 3);
    return;
  }
#endif
  // Separable, vertical pass first, 8.8 fixed point: the vertical sum (<= 255 * 256) is rounded
  // back to 8 bits of range so the horizontal pass also fits 16-bit lanes (the lost fraction is far
  // below what the binary tests can see). One padded 16-bit row buffer, reflected borders.
  const int w = src.cols, h = src.rows;
  uint16_t* t = row_filtered_.ptr<uint16_t>(0) + 3;  // t[-3 .. w+2] valid after padding
  const uint16_t k[7] = {uint16_t(kernel_[0]), uint16_t(kernel_[1]), uint16_t(kernel_[2]), uint16_t(kernel_[3]),
                         uint16_t(kernel_[4]), uint16_t(kernel_[5]), uint16_t(kernel_[6])};
  cv::v_uint16x8 vk[7];
  for (int i = 0; i < 7; ++i) vk[i] = cv::v_setall_u16(k[i]);
  const cv::v_uint16x8 half = cv::v_setall_u16(128);
  for (int y = y0; y < y1; ++y) {
    const uint8_t* r[7];
    for (int i = 0; i < 7; ++i) r[i] = src.ptr<uint8_t>(reflect101(y + i - 3, h));
    uint8_t* d = dst.ptr<uint8_t>(y);
    for (const Span* span = spans; span != spans + num_spans; ++span) {
      const int x0 = span->x0, x1 = span->x1;
      // The vertical pass covers the columns the horizontal one reads, [x0 - 3, x1 + 3) inside the
      // image; the 3 columns past an image edge are mirrored from inside it afterwards.
      const int vx0 = std::max(x0 - 3, 0), vx1 = std::min(x1 + 3, w);
      // Whole vector blocks; a partial last block is moved back to end at the range's end and
      // recomputes a few columns with the same values (so a small span needs no scalar tail).
      const int v_block_end = vx1 - vx0 >= 16 ? vx1 : vx0;
      const int h_block_end = x1 - x0 >= 8 ? x1 : x0;
      // The kernel is symmetric: rows 3 - i and 3 + i are added first (<= 510) and multiplied
      // once, 4 multiplies instead of 7 for the same integer sum (<= 65280: no overflow).
      for (int x = vx0; x < v_block_end;) {
        const int bx = std::min(x, v_block_end - 16);
        x = bx + 16;
        cv::v_uint16x8 lo, hi, a, b;
        cv::v_expand(cv::v_load(r[3] + bx), lo, hi);
        lo = cv::v_mul_wrap(lo, vk[3]);
        hi = cv::v_mul_wrap(hi, vk[3]);
        for (int i = 0; i < 3; ++i) {
          cv::v_uint16x8 c, e;
          cv::v_expand(cv::v_load(r[i] + bx), a, b);
          cv::v_expand(cv::v_load(r[6 - i] + bx), c, e);
          lo += cv::v_mul_wrap(a + c, vk[i]);
          hi += cv::v_mul_wrap(b + e, vk[i]);
        }
        cv::v_store(t + bx, (lo + half) >> 8);
        cv::v_store(t + bx + 8, (hi + half) >> 8);
      }
      blurVerticalScalar(r, kernel_.data(), v_block_end > vx0 ? vx1 : vx0, vx1, t);
      mirrorEdges(t, w, x0, x1);
      for (int x = x0; x < h_block_end;) {
        const int bx = std::min(x, h_block_end - 8);
        x = bx + 8;
        cv::v_uint16x8 acc = cv::v_mul_wrap(cv::v_load(t + bx), vk[3]);
        for (int i = 0; i < 3; ++i) acc += cv::v_mul_wrap(cv::v_load(t + bx + i - 3) + cv::v_load(t + bx + 3 - i), vk[i]);
        cv::v_pack_store(d + bx, (acc + half) >> 8);
      }
      blurHorizontalScalar(t, kernel_.data(), h_block_end > x0 ? x1 : x0, x1, d);
    }
  }
}

}  // namespace plumb

#include "pipeline/frontend/orb_descriptor.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include <opencv2/core/hal/intrin.hpp>

#include "pipeline/frontend/round_half_away.h"

// The x86 path: SSSE3's pmaddubsw for orientationDeg(), chosen at run time on x86-64 (the baseline
// is SSE2), and cmp + adc in describe(). Elsewhere (aarch64: NEON) the portable path alone.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <tmmintrin.h>
#define PLUMB_ORB_X86 1
#else
#define PLUMB_ORB_X86 0
#endif

namespace plumb {
namespace {

#if PLUMB_ORB_X86
bool cpuHasSsse3() {
  static const bool has = __builtin_cpu_supports("ssse3");
  return has;
}

#define PLUMB_ORIENTATION_TARGET __attribute__((target("ssse3")))

// The sum of the four 32-bit lanes.
PLUMB_ORIENTATION_TARGET inline int sumLanes(__m128i v) {
  v = _mm_add_epi32(v, _mm_shuffle_epi32(v, _MM_SHUFFLE(1, 0, 3, 2)));
  v = _mm_add_epi32(v, _mm_shuffle_epi32(v, _MM_SHUFFLE(2, 3, 0, 1)));
  return _mm_cvtsi128_si32(v);
}

// m10 and m01 of orientationDeg() with pmaddubsw (unsigned pixel bytes times signed weight
// bytes, adjacent products summed into 16 bits). A pair sum is at most 255 * 30 in magnitude (no
// saturation). Per pair of rows +-dy, 16-bit lane j of the sums of the two 16-pixel halves holds
// pixels 2j, 2j + 1, 2j + 16 and 2j + 17 of a row: for m10 |sum| <= 2 rows * 255 * (15 + 14 + 1
// + 2) = 16320, for m01 each row's part is in [0, 255 * 4 * 15 = 15300] and their difference in
// [-15300, 15300]: no 16-bit lane wraps. Each row pair is then widened to 32 bits by a
// multiply-add with ones, so the totals are the portable path's exact integers (and the angle
// the same float).
PLUMB_ORIENTATION_TARGET float orientationBytes(const uint8_t* p, int stride, const std::array<int8_t, 32>* x_weight,
                                                const std::array<int8_t, 32>* y_weight, int radius) {
  const __m128i ones = _mm_set1_epi16(1);
#define PLUMB_LOAD(a) _mm_loadu_si128(reinterpret_cast<const __m128i*>(a))
#define PLUMB_WEIGHTS(a) _mm_load_si128(reinterpret_cast<const __m128i*>(a))
  __m128i m10 = _mm_madd_epi16(_mm_add_epi16(_mm_maddubs_epi16(PLUMB_LOAD(p - radius), PLUMB_WEIGHTS(x_weight[0].data())),
                                             _mm_maddubs_epi16(PLUMB_LOAD(p - radius + 16), PLUMB_WEIGHTS(x_weight[0].data() + 16))),
                               ones);
  __m128i m01 = _mm_setzero_si128();
  for (int dy = 1; dy <= radius; ++dy) {
    const uint8_t* below = p + dy * stride - radius;
    const uint8_t* above = p - dy * stride - radius;
    const __m128i b0 = PLUMB_LOAD(below), b1 = PLUMB_LOAD(below + 16);
    const __m128i a0 = PLUMB_LOAD(above), a1 = PLUMB_LOAD(above + 16);
    const __m128i wx0 = PLUMB_WEIGHTS(x_weight[dy].data()), wx1 = PLUMB_WEIGHTS(x_weight[dy].data() + 16);
    const __m128i wy0 = PLUMB_WEIGHTS(y_weight[dy].data()), wy1 = PLUMB_WEIGHTS(y_weight[dy].data() + 16);
    const __m128i s10 = _mm_add_epi16(_mm_add_epi16(_mm_maddubs_epi16(b0, wx0), _mm_maddubs_epi16(b1, wx1)),
                                      _mm_add_epi16(_mm_maddubs_epi16(a0, wx0), _mm_maddubs_epi16(a1, wx1)));
    const __m128i s01 = _mm_sub_epi16(_mm_add_epi16(_mm_maddubs_epi16(b0, wy0), _mm_maddubs_epi16(b1, wy1)),
                                      _mm_add_epi16(_mm_maddubs_epi16(a0, wy0), _mm_maddubs_epi16(a1, wy1)));
    m10 = _mm_add_epi32(m10, _mm_madd_epi16(s10, ones));
    m01 = _mm_add_epi32(m01, _mm_madd_epi16(s01, ones));
  }
#undef PLUMB_LOAD
#undef PLUMB_WEIGHTS
  return cv::fastAtan2(static_cast<float>(sumLanes(m01)), static_cast<float>(sumLanes(m10)));
}
#endif

// Small deterministic generator (64-bit LCG) so the pattern is identical on every platform
// and standard library (std::normal_distribution is not specified bit for bit).
class PatternRandom {
 public:
  double uniform() {
    state_ = state_ * 6364136223846793005ULL + 1442695040888963407ULL;
    return ((state_ >> 11) + 0.5) * (1.0 / 9007199254740992.0);
  }
  double gaussian() {  // Box-Muller
    const double u1 = uniform(), u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }

 private:
  uint64_t state_ = 0x9E3779B97F4A7C15ULL;
};

}  // namespace

OrbDescriber::OrbDescriber(int stride) : stride_(stride) {
  for (int dy = 0; dy <= kPatchRadius; ++dy) {
    disc_half_width_[dy] = static_cast<int>(std::floor(std::sqrt(double(kPatchRadius * kPatchRadius - dy * dy)) + 0.5));
    // Weights of the 32 pixels p[-15 .. 16] of the rows +-dy (the last one is always outside).
    for (int i = 0; i < 32; ++i) {
      const int dx = i - kPatchRadius;
      const bool inside = std::abs(dx) <= disc_half_width_[dy];
      x_weight_[dy][i] = static_cast<int16_t>(inside ? dx : 0);
      y_weight_[dy][i] = static_cast<int16_t>(inside ? dy : 0);
      x_weight_bytes_[dy][i] = static_cast<int8_t>(x_weight_[dy][i]);
      y_weight_bytes_[dy][i] = static_cast<int8_t>(y_weight_[dy][i]);
    }
  }
  setKernelPath(KernelPath::kX86);  // where the CPU has it
  constexpr double kSigma = 31.0 / 5.0;
  constexpr double kMaxRadius = 13.0;
  std::array<double, 1024> pattern{};  // x0 y0 x1 y1 per test
  PatternRandom random;
  for (int i = 0; i < 512; ++i) {
    double x, y;
    do {
      x = random.gaussian() * kSigma;
      y = random.gaussian() * kSigma;
    } while (x * x + y * y > kMaxRadius * kMaxRadius);
    pattern[2 * i] = x;
    pattern[2 * i + 1] = y;
  }
  std::array<std::array<int, 2 * kMaxSampleReach + 1>, kAngleBins> row_min{}, row_max{};
  for (auto& rows : row_min) rows.fill(kMaxSampleReach + 1);
  for (auto& rows : row_max) rows.fill(-kMaxSampleReach - 1);
  for (int bin = 0; bin < kAngleBins; ++bin) {
    const double a = bin * 2.0 * M_PI / kAngleBins;
    const double c = std::cos(a), s = std::sin(a);
    for (int i = 0; i < 512; ++i) {
      const double x = pattern[2 * i], y = pattern[2 * i + 1];
      const int rx = static_cast<int>(std::lround(c * x - s * y));
      const int ry = static_cast<int>(std::lround(s * x + c * y));
      sample_reach_ = std::max(sample_reach_, std::max(std::abs(rx), std::abs(ry)));
      CV_Assert(sample_reach_ <= kMaxSampleReach);  // radius 13 rounded: 13
      row_min[bin][ry + kMaxSampleReach] = std::min(row_min[bin][ry + kMaxSampleReach], rx);
      row_max[bin][ry + kMaxSampleReach] = std::max(row_max[bin][ry + kMaxSampleReach], rx);
      // Test i compares sample 2i (first) with sample 2i + 1 (second).
      (i % 2 == 0 ? first_offsets_ : second_offsets_)[bin][i / 2] = ry * stride_ + rx;
    }
  }
  for (int bin = 0; bin < kAngleBins; ++bin) {
    for (int row = 0; row < 2 * kMaxSampleReach + 1; ++row) {
      uint64_t mask = 0;
      for (int dx = row_min[bin][row]; dx <= row_max[bin][row]; ++dx) mask |= uint64_t{1} << (dx + sample_reach_);
      sample_row_masks_[bin][row] = mask;
    }
  }
}

int OrbDescriber::angleBin(float angle_deg) {
  int bin = static_cast<int>(roundHalfAwayFromZero(angle_deg * (kAngleBins / 360.0f)));
  if (bin >= kAngleBins) bin -= kAngleBins;
  if (bin < 0) bin += kAngleBins;
  return bin;
}

bool OrbDescriber::setKernelPath(KernelPath path) {
#if PLUMB_ORB_X86
  if (path == KernelPath::kX86 && !cpuHasSsse3()) return false;
#else
  if (path == KernelPath::kX86) return false;
#endif
  kernel_path_ = path;
  return true;
}

float OrbDescriber::orientationDeg(const uint8_t* p) const {
#if PLUMB_ORB_X86
  if (kernel_path_ == KernelPath::kX86) {
    return orientationBytes(p, stride_, x_weight_bytes_.data(), y_weight_bytes_.data(), kPatchRadius);
  }
#endif
  // m10 = sum x I, m01 = sum y I over the disc. Rows +-dy together, 16 pixels per vector:
  // m10 gets dx * (below + above), m01 gets dy * (below - above), as 16-bit products summed in
  // pairs into 32-bit lanes (exact integers: the order of the additions does not matter).
  cv::v_int32x4 m10 = cv::v_setzero_s32(), m01 = cv::v_setzero_s32();
  for (int half = 0; half < 2; ++half) {  // centre row: dy = 0, weights dx
    cv::v_uint16x8 lo, hi;
    cv::v_expand(cv::v_load(p - kPatchRadius + 16 * half), lo, hi);
    m10 += cv::v_dotprod(cv::v_reinterpret_as_s16(lo), cv::v_load(x_weight_[0].data() + 16 * half));
    m10 += cv::v_dotprod(cv::v_reinterpret_as_s16(hi), cv::v_load(x_weight_[0].data() + 16 * half + 8));
  }
  for (int dy = 1; dy <= kPatchRadius; ++dy) {
    const uint8_t* below = p + dy * stride_ - kPatchRadius;
    const uint8_t* above = p - dy * stride_ - kPatchRadius;
    for (int half = 0; half < 2; ++half) {
      cv::v_uint16x8 b_lo, b_hi, a_lo, a_hi;
      cv::v_expand(cv::v_load(below + 16 * half), b_lo, b_hi);
      cv::v_expand(cv::v_load(above + 16 * half), a_lo, a_hi);
      const int16_t* wx = x_weight_[dy].data() + 16 * half;
      const int16_t* wy = y_weight_[dy].data() + 16 * half;
      m10 += cv::v_dotprod(cv::v_reinterpret_as_s16(b_lo + a_lo), cv::v_load(wx));
      m10 += cv::v_dotprod(cv::v_reinterpret_as_s16(b_hi + a_hi), cv::v_load(wx + 8));
      m01 += cv::v_dotprod(cv::v_reinterpret_as_s16(b_lo) - cv::v_reinterpret_as_s16(a_lo), cv::v_load(wy));
      m01 += cv::v_dotprod(cv::v_reinterpret_as_s16(b_hi) - cv::v_reinterpret_as_s16(a_hi), cv::v_load(wy + 8));
    }
  }
  return cv::fastAtan2(static_cast<float>(cv::v_reduce_sum(m01)), static_cast<float>(cv::v_reduce_sum(m10)));
}

void OrbDescriber::describe(const uint8_t* p, float angle_deg, Descriptor256& out) const {
  const int bin = angleBin(angle_deg);
  const int* first = first_offsets_[bin].data();
  const int* second = second_offsets_[bin].data();
  // Test t is bit t % 64 of word t / 64, shifted in from the last test of a word down.
#if PLUMB_ORB_X86
  if (kernel_path_ == KernelPath::kX86) {
    // cmp sets the carry exactly when p[first] < p[second] (unsigned bytes) and adc shifts it in
    // (bits + bits + carry): 5 instructions a test (two offsets, a byte load, the compare with
    // memory, adc) where the portable form compiles to 7 (setb, a widening and lea for the adc).
    for (int word = 0; word < 4; ++word, first += 64, second += 64) {
      uint64_t bits = 0;
#pragma GCC unroll 64
      for (int j = 63; j >= 0; --j) {
        const uint8_t a = p[first[j]];
        asm("cmpb %2, %1\n\tadcq %0, %0" : "+r"(bits) : "q"(a), "m"(p[second[j]]) : "cc");
      }
      out.words[word] = bits;
    }
    return;
  }
#endif
  // Scalar compares, unrolled: ~7 instructions a test (two offsets, a byte load, a compare with
  // memory, setb, a widening, lea); gathering 16 samples into byte vectors for one vector compare
  // cost ~11 (GCC assembles the gathered bytes with shifts and ors).
  for (int word = 0; word < 4; ++word, first += 64, second += 64) {
    uint64_t bits = 0;
#pragma GCC unroll 64
    for (int j = 63; j >= 0; --j) bits = bits + bits + static_cast<uint64_t>(p[first[j]] < p[second[j]]);
    out.words[word] = bits;
  }
}

}  // namespace plumb

#include "pipeline/frontend/orb_descriptor.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include <opencv2/core/hal/intrin.hpp>

namespace plumb {
namespace {

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
    }
  }
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
  for (int bin = 0; bin < kAngleBins; ++bin) {
    const double a = bin * 2.0 * M_PI / kAngleBins;
    const double c = std::cos(a), s = std::sin(a);
    for (int i = 0; i < 512; ++i) {
      const double x = pattern[2 * i], y = pattern[2 * i + 1];
      const int rx = static_cast<int>(std::lround(c * x - s * y));
      const int ry = static_cast<int>(std::lround(s * x + c * y));
      sample_reach_ = std::max(sample_reach_, std::max(std::abs(rx), std::abs(ry)));
      // Test i compares sample 2i (first) with sample 2i + 1 (second).
      (i % 2 == 0 ? first_offsets_ : second_offsets_)[bin][i / 2] = ry * stride_ + rx;
    }
  }
}

float OrbDescriber::orientationDeg(const uint8_t* p) const {
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
  int bin = static_cast<int>(std::lround(angle_deg * (kAngleBins / 360.0f)));
  if (bin >= kAngleBins) bin -= kAngleBins;
  if (bin < 0) bin += kAngleBins;
  const int* first = first_offsets_[bin].data();
  const int* second = second_offsets_[bin].data();
  // Test t is bit t % 64 of word t / 64, shifted in from the last test of a word down. Scalar
  // compares, unrolled: ~7 instructions a test (two offsets, a byte load, a compare with memory,
  // setb, a widening, lea); gathering 16 samples into byte vectors for one vector compare cost
  // ~11 (GCC assembles the gathered bytes with shifts and ors).
  for (int word = 0; word < 4; ++word, first += 64, second += 64) {
    uint64_t bits = 0;
#pragma GCC unroll 64
    for (int j = 63; j >= 0; --j) bits = bits + bits + static_cast<uint64_t>(p[first[j]] < p[second[j]]);
    out.words[word] = bits;
  }
}

}  // namespace plumb

#include "pipeline/orb_descriptor.h"

#include <cmath>

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
      offsets_[bin][i] = ry * stride_ + rx;
    }
  }
}

float OrbDescriber::orientationDeg(const uint8_t* p) const {
  // m10 = sum x I, m01 = sum y I over the disc; rows +-dy are handled together.
  int m10 = 0, m01 = 0;
  for (int dx = -kPatchRadius; dx <= kPatchRadius; ++dx) m10 += dx * p[dx];
  for (int dy = 1; dy <= kPatchRadius; ++dy) {
    const uint8_t* below = p + dy * stride_;
    const uint8_t* above = p - dy * stride_;
    const int w = disc_half_width_[dy];
    int v_sum = 0;
    for (int dx = -w; dx <= w; ++dx) {
      const int b = below[dx], a = above[dx];
      v_sum += b - a;
      m10 += dx * (b + a);
    }
    m01 += dy * v_sum;
  }
  return cv::fastAtan2(static_cast<float>(m01), static_cast<float>(m10));
}

void OrbDescriber::describe(const uint8_t* p, float angle_deg, Descriptor256& out) const {
  int bin = static_cast<int>(std::lround(angle_deg * (kAngleBins / 360.0f)));
  if (bin >= kAngleBins) bin -= kAngleBins;
  if (bin < 0) bin += kAngleBins;
  const int* o = offsets_[bin].data();
  for (int w = 0; w < 4; ++w) {
    uint64_t word = 0;
    for (int b = 0; b < 64; ++b, o += 2) word |= static_cast<uint64_t>(p[o[0]] < p[o[1]]) << b;
    out.words[w] = word;
  }
}

}  // namespace plumb

#pragma once
// Direction bins of a frame's lines, so the line matcher tests a candidate only against the lines
// whose direction can pass its angle test (matcher.h: within max_angle_deg, undirected).
//
// The undirected directions [0, 180) deg are cut into kBins bins. A line is put into every bin
// that holds a direction within max_angle_deg + kMarginDeg of its own, so a line left out of a
// candidate's bin differs from the candidate by more than max_angle_deg + kMarginDeg and fails the
// matcher's float test |u . span| < cos(max_angle) |span| (whose rounding moves the boundary by
// ~1e-3 deg, far inside the margin). The bins are therefore a superset of the lines that pass,
// listed in increasing index: the matcher visits the same passing lines in the same order and
// returns exactly the matches of testing every line (tests/pipeline/odometry/matcher_test.cpp
// compares both on random lines). Lines or candidates whose direction is not finite, and angle
// windows that cover every direction, fall back to every line.
#include <array>
#include <cmath>
#include <cstdint>

#include <Eigen/Core>

#include "pipeline/frontend/capacities.h"

namespace plumb {

class LineDirectionBins {
 public:
  static constexpr int kBins = 45;  // 4 deg each: ~14 % of the lines per bin at the default 10 deg
  static constexpr double kBinDeg = 180.0 / kBins;
  static constexpr double kMarginDeg = 1.0;
  static constexpr int kWords = (kMaxLines + 63) / 64;
  using Mask = std::array<uint64_t, kWords>;

  // spans[k] = end - start of line k (k < count <= kMaxLines); lines shorter than min_length
  // (which the matcher skips) go into no bin.
  void build(const Eigen::Vector2f* spans, const float* lengths, int count, float min_length,
             float max_angle_deg) {
    for (Mask& m : masks_) m.fill(0);
    all_.fill(0);
    for (int k = 0; k < count; ++k) all_[k / 64] |= uint64_t(1) << (k % 64);
    const double window_deg = std::abs(double(max_angle_deg)) + kMarginDeg;
    every_line_ = !(2.0 * window_deg + kBinDeg < 180.0);  // also for a NaN angle
    if (every_line_) return;
    for (int k = 0; k < count; ++k) {
      if (lengths[k] < min_length) continue;
      const uint64_t bit = uint64_t(1) << (k % 64);
      const double angle = undirectedAngleDeg(spans[k]);
      if (!std::isfinite(angle) || !std::isfinite(lengths[k])) {
        for (Mask& m : masks_) m[k / 64] |= bit;
        continue;
      }
      // angle in [0, 180] and window_deg < 90: first >= -kBins, last < 2 kBins.
      const int first = int(std::floor((angle - window_deg) / kBinDeg));
      const int last = int(std::floor((angle + window_deg) / kBinDeg));
      for (int b = first; b <= last; ++b) masks_[b < 0 ? b + kBins : (b >= kBins ? b - kBins : b)][k / 64] |= bit;
    }
  }

  // The lines to test against a candidate of direction `direction` (any length).
  const Mask& near(const Eigen::Vector2f& direction) const {
    if (every_line_) return all_;
    const double angle = undirectedAngleDeg(direction);
    if (!std::isfinite(angle)) return all_;
    const int b = int(angle / kBinDeg);
    return masks_[b >= kBins ? b - kBins : b];
  }

  // Undirected direction in [0, 180] deg; NaN for a vector whose squared norm is not finite in
  // float (the matcher's products with it may then overflow, so such a vector gets every line).
  static double undirectedAngleDeg(const Eigen::Vector2f& v) {
    if (!std::isfinite(v.squaredNorm())) return NAN;
    double angle = std::atan2(double(v.y()), double(v.x())) * (180.0 / M_PI);
    if (angle < 0.0) angle += 180.0;
    return angle < 0.0 ? 0.0 : angle;  // -0 and rounding; 180 itself wraps to bin 0 in near()
  }

 private:
  std::array<Mask, kBins> masks_{};
  Mask all_{};
  bool every_line_ = true;
};

// Calls f(k) for every set bit k of `mask` in increasing order.
template <typename F>
inline void forEachLine(const LineDirectionBins::Mask& mask, F&& f) {
  for (int w = 0; w < LineDirectionBins::kWords; ++w) {
    uint64_t bits = mask[w];
    while (bits != 0) {
      f(w * 64 + __builtin_ctzll(bits));
      bits &= bits - 1;
    }
  }
}

}  // namespace plumb

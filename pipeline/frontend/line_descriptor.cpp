#include "pipeline/frontend/line_descriptor.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <opencv2/core/hal/intrin.hpp>

namespace plumb {
namespace {

constexpr int kBands = 9;
constexpr int kStats = 8;  // 4 LBD sums x 2 halves of the segment

// LBD's global Gaussian across the region (sigma = half the rows) at row r of `rows`.
float rowWeight(int r, int rows) {
  const float offset = static_cast<float>(r - rows / 2);
  const float sigma = 0.5f * rows;
  return std::exp(-0.5f * offset * offset / (sigma * sigma));
}

// The weights depend on the row count alone: those of the default band width (3) once, not an
// exp per row of every descriptor (the same calls, so the same values).
constexpr int kDefaultRows = kBands * 3;
const std::array<float, kDefaultRows>& defaultRowWeights() {
  static const std::array<float, kDefaultRows> weights = [] {
    std::array<float, kDefaultRows> w{};
    for (int r = 0; r < kDefaultRows; ++r) w[r] = rowWeight(r, kDefaultRows);
    return w;
  }();
  return weights;
}

}  // namespace

void computeLineDescriptor(const cv::Mat& image, const cv::Point2f& start, const cv::Point2f& end,
                           const LineDescriptorOptions& options, Descriptor256& out) {
  std::array<std::array<float, kStats>, kBands> band{};
  const float dx = end.x - start.x, dy = end.y - start.y;
  const float length = std::sqrt(dx * dx + dy * dy);
  out.words = {0, 0, 0, 0};
  if (length < 1e-3f) return;
  const float ux = dx / length, uy = dy / length;  // along the segment
  const float nx = -uy, ny = ux;                   // across it
  const int w = std::max(1, options.band_width);
  const int rows = kBands * w;
  const int half_rows = rows / 2;
  const int positions = std::clamp(static_cast<int>(length), 4, std::max(4, options.max_positions));
  const std::array<float, kDefaultRows>& default_weights = defaultRowWeights();
  const float step_x = dx / positions, step_y = dy / positions;
  const int x_max = image.cols - 2, y_max = image.rows - 2;
  const int stride = static_cast<int>(image.step[0]);
  const uint8_t* data = image.ptr<uint8_t>(0);
  const cv::v_float32x4 x_proj(nx, -nx, ux, -ux), y_proj(ny, -ny, uy, -uy), v_zero = cv::v_setzero_f32();

  for (int r = 0; r < rows; ++r) {
    const float offset = static_cast<float>(r - half_rows);
    const float weight = rows == kDefaultRows ? default_weights[r] : rowWeight(r, rows);
    const cv::v_float32x4 v_weight = cv::v_setall_f32(weight);
    std::array<float, kStats>& stats = band[r / w];
    // Walk the row incrementally; +0.5 then truncation rounds (coordinates are >= 0 inside).
    // The first and second half of the positions feed separate sums.
    float fx = start.x + 0.5f * step_x + offset * nx + 0.5f, fy = start.y + 0.5f * step_y + offset * ny + 0.5f;
    const int half_end[2] = {(positions + 1) / 2, positions};  // 2k >= positions: second half
    // Whether every sample of the row is inside (x, y in [1, max]): the positions are monotone in
    // k (adding a constant step rounds monotonically), so the first and the last decide; the last
    // is estimated as fx + (positions - 1) step, within `margin` of the running sum's value. Rows
    // inside take the loop without the per-sample tests (the same samples either way). A sum of
    // n float steps is within n half-ulps (<= 6e-8 |value| each) of the product form.
    const float last_fx = fx + (positions - 1) * step_x, last_fy = fy + (positions - 1) * step_y;
    const float magnitude = std::abs(fx) + std::abs(fy) + std::abs(last_fx) + std::abs(last_fy) + 1;
    const float margin = 0.05f + 4e-7f * positions * magnitude;
    const bool inside = std::min(fx, last_fx) >= 1 + margin && std::min(fy, last_fy) >= 1 + margin &&
                        std::max(fx, last_fx) < x_max + 1 - margin && std::max(fy, last_fy) < y_max + 1 - margin;
    for (int part = 0, k = 0; part < 2; ++part) {
      // Lanes (across+, across-, along+, along-): the sample's projections onto (n, -n, u, -u),
      // clamped at 0, added to the band's running sums in the same order as a scalar loop would
      // (negation is exact, and adding the +-0 of the other sign leaves a sum unchanged).
      float* s = stats.data() + 4 * part;
      cv::v_float32x4 sums = cv::v_load(s);
      auto add = [&](int x, int y) {
        const uint8_t* p = data + y * stride + x;
        const cv::v_float32x4 gx = cv::v_setall_f32(static_cast<float>(p[1] - p[-1]));
        const cv::v_float32x4 gy = cv::v_setall_f32(static_cast<float>(p[stride] - p[-stride]));
        sums += cv::v_max((gx * x_proj + gy * y_proj) * v_weight, v_zero);
      };
      if (inside) {
        for (; k < half_end[part]; ++k, fx += step_x, fy += step_y) add(static_cast<int>(fx), static_cast<int>(fy));
      } else {
        for (; k < half_end[part]; ++k, fx += step_x, fy += step_y) {
          if (fx < 1 || fy < 1) continue;
          const int x = static_cast<int>(fx), y = static_cast<int>(fy);
          if (x < 1 || y < 1 || x > x_max || y > y_max) continue;
          add(x, y);
        }
      }
      cv::v_store(s, sums);
    }
  }

  // The comparisons 4 at a time, as sign masks: 208 bits of 8 (one pair of bands: s = 0..7, so
  // no group crosses a 64-bit word), then 8 groups of 6 within bands, all in the last word.
  int bit = 0;
  for (int i = 0; i < kBands; ++i) {
    const cv::v_float32x4 lo_i = cv::v_load(band[i].data()), hi_i = cv::v_load(band[i].data() + 4);
    for (int j = i + 1; j < kBands && j - i <= 4; ++j) {
      const cv::v_float32x4 lo_j = cv::v_load(band[j].data()), hi_j = cv::v_load(band[j].data() + 4);
      const uint64_t bits = static_cast<uint64_t>(cv::v_signmask(lo_i > lo_j) | cv::v_signmask(hi_i > hi_j) << 4);
      out.words[bit >> 6] |= bits << (bit & 63);
      bit += 8;
    }
  }
  for (int i = 0; i < kBands - 1; ++i) {  // 8 bands x 6 = 48 bits
    // (b0 > b1, b4 > b5, b2 > b3, b6 > b7), then (b0 > b4, b1 > b5).
    const cv::v_float32x4 lo = cv::v_load(band[i].data()), hi = cv::v_load(band[i].data() + 4);
    cv::v_float32x4 z0, z1;
    cv::v_zip(lo, hi, z0, z1);  // (b0, b4, b1, b5), (b2, b6, b3, b7)
    const int pairs = cv::v_signmask(cv::v_combine_low(z0, z1) > cv::v_combine_high(z0, z1));
    const int halves = cv::v_signmask(lo > hi) & 3;
    out.words[bit >> 6] |= static_cast<uint64_t>(pairs | halves << 4) << (bit & 63);
    bit += 6;
  }
}

}  // namespace plumb

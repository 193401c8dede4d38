#include "pipeline/frontend/line_descriptor.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <opencv2/core/hal/intrin.hpp>

namespace plumb {
namespace {

constexpr int kBands = 9;
constexpr int kStats = 8;  // 4 LBD sums x 2 halves of the segment

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
  const float sigma = 0.5f * rows;  // LBD's global Gaussian across the region
  const int x_max = image.cols - 2, y_max = image.rows - 2;
  const int stride = static_cast<int>(image.step[0]);
  const uint8_t* data = image.ptr<uint8_t>(0);
  const cv::v_float32x4 x_proj(nx, -nx, ux, -ux), y_proj(ny, -ny, uy, -uy), v_zero = cv::v_setzero_f32();

  for (int r = 0; r < rows; ++r) {
    const float offset = static_cast<float>(r - half_rows);
    const float weight = std::exp(-0.5f * offset * offset / (sigma * sigma));
    const cv::v_float32x4 v_weight = cv::v_setall_f32(weight);
    std::array<float, kStats>& stats = band[r / w];
    // Walk the row incrementally; +0.5 then truncation rounds (coordinates are >= 0 inside).
    // The first and second half of the positions feed separate sums.
    const float step_x = dx / positions, step_y = dy / positions;
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

  int bit = 0;
  auto put = [&](bool value) {
    if (value) out.words[bit >> 6] |= 1ULL << (bit & 63);
    ++bit;
  };
  for (int i = 0; i < kBands; ++i) {
    for (int j = i + 1; j < kBands && j - i <= 4; ++j) {
      for (int s = 0; s < kStats; ++s) put(band[i][s] > band[j][s]);
    }
  }
  for (int i = 0; i < kBands - 1; ++i) {  // 8 bands x 6 = 48 bits
    const std::array<float, kStats>& b = band[i];
    put(b[0] > b[1]);
    put(b[4] > b[5]);
    put(b[2] > b[3]);
    put(b[6] > b[7]);
    put(b[0] > b[4]);
    put(b[1] > b[5]);
  }
}

}  // namespace plumb

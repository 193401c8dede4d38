#include "pipeline/frontend/depth_registration.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace plumb {
namespace {

// Colour points nearer than this are dropped (behind the colour camera, or inside its housing).
constexpr float kMinColourZ = 0.01f;
// A footprint wider than this many colour pixels per side is cut to it: only a depth camera with
// far fewer pixels than the colour camera gets there, and then a coarser splat is all it can give.
constexpr int kMaxFootprintPx = 8;
// Footprints are grown by this much per side. Two neighbours on one slanted surface have different
// depths, so the baseline's parallax (t / z) moves them by different amounts and opens sub-pixel
// gaps between their footprints (~0.01 px at 2.5 m on a 30 degree slant with a 2.5 cm baseline,
// ~0.2 px at 0.5 m on a 60 degree one) through which a colour pixel centre would fall. Where grown
// footprints overlap the z-buffer keeps the nearer sample: foreground edges grow by at most this.
constexpr double kFootprintGrowthPx = 0.25;

}  // namespace

DepthRegistration::DepthRegistration(const PinholeCamera& camera) : colour_(camera) {
  if (!camera.depth_camera) return;
  const DepthCamera& d = *camera.depth_camera;
  active_ = true;
  depth_width_ = d.width;
  depth_height_ = d.height;
  const Eigen::Isometry3d T_colour_depth = d.T_colour_depth();
  const Eigen::Matrix3d R = T_colour_depth.linear();
  tx_ = float(T_colour_depth.translation().x());
  ty_ = float(T_colour_depth.translation().y());
  tz_ = float(T_colour_depth.translation().z());
  const PinholeCamera lens = depthCameraLens(d);
  // A depth pixel's ray in the colour frame (depth camera z = 1), and that point's colour pixel.
  auto rayOf = [&](double u, double v) {
    const Eigen::Vector2d ideal = lens.undistortPoint(u, v);
    return Eigen::Vector3d(R * Eigen::Vector3d((ideal.x() - d.cx) / d.fx, (ideal.y() - d.cy) / d.fy, 1.0));
  };
  auto colourPixelOf = [&](const Eigen::Vector3d& P) {
    return camera.distortPoint(camera.fx * P.x() / P.z() + camera.cx, camera.fy * P.y() / P.z() + camera.cy);
  };
  // Colour pixels of the depth pixels' corners (a (w+1) x (h+1) grid, each corner shared by four
  // pixels), at unit depth without the translation.
  const int grid_width = d.width + 1;
  std::vector<Eigen::Vector2d> corners(std::size_t(grid_width) * (d.height + 1));
  for (int v = 0; v <= d.height; ++v) {
    for (int u = 0; u <= d.width; ++u) {
      const Eigen::Vector3d corner = rayOf(u - 0.5, v - 0.5);
      corners[std::size_t(v) * grid_width + u] = corner.z() > 0 ? colourPixelOf(corner) : Eigen::Vector2d(0, 0);
    }
  }
  const std::size_t count = std::size_t(d.width) * d.height;
  for (std::vector<float>* table : {&ray_x_, &ray_y_, &ray_z_, &half_w_, &half_h_}) table->resize(count);
  for (std::vector<int32_t>* row : {&x0_, &x1_, &y0_, &y1_, &raw_}) row->resize(std::size_t(d.width));
  ceil_offset_ = float(std::max(camera.width, camera.height) + 16);
  for (int v = 0; v < d.height; ++v) {
    for (int u = 0; u < d.width; ++u) {
      const std::size_t i = std::size_t(v) * d.width + u;
      const Eigen::Vector3d ray = rayOf(u, v);
      ray_x_[i] = float(ray.x());
      ray_y_[i] = float(ray.y());
      ray_z_[i] = float(ray.z());
      const Eigen::Vector2d* top = &corners[std::size_t(v) * grid_width + u];
      const Eigen::Vector2d* bottom = top + grid_width;
      const double u0 = std::min({top[0].x(), top[1].x(), bottom[0].x(), bottom[1].x()});
      const double u1 = std::max({top[0].x(), top[1].x(), bottom[0].x(), bottom[1].x()});
      const double v0 = std::min({top[0].y(), top[1].y(), bottom[0].y(), bottom[1].y()});
      const double v1 = std::max({top[0].y(), top[1].y(), bottom[0].y(), bottom[1].y()});
      half_w_[i] = float(std::min(0.5 * (u1 - u0) + kFootprintGrowthPx, 0.5 * kMaxFootprintPx));
      half_h_[i] = float(std::min(0.5 * (v1 - v0) + kFootprintGrowthPx, 0.5 * kMaxFootprintPx));
    }
  }
}

bool DepthRegistration::registerInto(const cv::Mat& depth, double depth_factor, cv::Mat& out) {
  if (!active_ || depth.type() != CV_16UC1 || depth.cols != depth_width_ || depth.rows != depth_height_ ||
      !(depth_factor > 0)) {
    return false;
  }
  out.create(colour_.height, colour_.width, CV_16UC1);  // no-op once sized
  for (int r = 0; r < out.rows; ++r) std::memset(out.ptr<uint16_t>(r), 0, std::size_t(out.cols) * sizeof(uint16_t));
  const float to_metres = float(1.0 / depth_factor), to_raw = float(depth_factor);
  const bool distortion = colour_.hasDistortion();
  for (int v = 0; v < depth_height_; ++v) {
    if (distortion) {
      projectRow<true>(v, depth.ptr<uint16_t>(v), to_metres, to_raw);
    } else {
      projectRow<false>(v, depth.ptr<uint16_t>(v), to_metres, to_raw);
    }
    splatRow(out);
  }
  return true;
}

// Branch-free over the row (vectorised): every pixel gets a footprint, empty for no reading, for
// points nearer than kMinColourZ and for z beyond the raw range.
template <bool kColourDistortion>
void DepthRegistration::projectRow(int v, const uint16_t* depth_row, float to_metres, float to_raw) {
  const std::size_t offset = std::size_t(v) * depth_width_;
  const float* __restrict ray_x = ray_x_.data() + offset;
  const float* __restrict ray_y = ray_y_.data() + offset;
  const float* __restrict ray_z = ray_z_.data() + offset;
  const float* __restrict half_w = half_w_.data() + offset;
  const float* __restrict half_h = half_h_.data() + offset;
  int32_t* __restrict x0 = x0_.data();
  int32_t* __restrict x1 = x1_.data();
  int32_t* __restrict y0 = y0_.data();
  int32_t* __restrict y1 = y1_.data();
  int32_t* __restrict raw = raw_.data();
  const float fx = float(colour_.fx), fy = float(colour_.fy), cx = float(colour_.cx), cy = float(colour_.cy);
  const float k1 = float(colour_.k1), k2 = float(colour_.k2), k3 = float(colour_.k3);
  const float p1 = float(colour_.p1), p2 = float(colour_.p2);
  const float width = float(colour_.width), height = float(colour_.height);
  const float tx = tx_, ty = ty_, tz = tz_, ceil_offset = ceil_offset_;
  const int n = depth_width_;  // a local: the stores cannot change it, so the loop count is known
  for (int u = 0; u < n; ++u) {
    const float z_depth = float(depth_row[u]) * to_metres;
    const float Z = z_depth * ray_z[u] + tz;
    const float raw_f = Z * to_raw + 0.5f;
    // `&` not `&&`: no branch, so the loop vectorises (depth 0 gives Z = t_z, below kMinColourZ
    // for any plausible camera, but is excluded on its own).
    const bool valid = (depth_row[u] != 0) & (Z >= kMinColourZ) & (raw_f < 65536.0f);
    const float inv_Z = 1.0f / (Z > kMinColourZ ? Z : kMinColourZ);
    float x = (z_depth * ray_x[u] + tx) * inv_Z, y = (z_depth * ray_y[u] + ty) * inv_Z;
    if (kColourDistortion) {  // PinholeCamera::distortPoint, in float
      const float r2 = x * x + y * y;
      const float radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
      const float xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
      const float yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
      x = xd;
      y = yd;
    }
    const float uc = fx * x + cx, vc = fy * y + cy;
    // Footprint at this depth: the colour pixels whose centres it holds (half-open intervals, so
    // neighbouring footprints of one surface neither overlap nor leave a gap), clamped to the
    // image, then ceil(b) = offset - trunc(offset - b) (libm's ceil is a call without SSE4.1).
    const float scale = 1.0f - tz * inv_Z;
    const float max_half = 0.5f * kMaxFootprintPx;  // a nearby point seen with t_z < 0 grows without bound
    const float hw_scaled = half_w[u] * scale, hh_scaled = half_h[u] * scale;
    const float hw = hw_scaled < max_half ? hw_scaled : max_half, hh = hh_scaled < max_half ? hh_scaled : max_half;
    auto ceilIn = [ceil_offset](float b, float limit) {
      const float clamped = b < 0.0f ? 0.0f : (b > limit ? limit : b);
      return int32_t(ceil_offset) - int32_t(ceil_offset - clamped);
    };
    const int32_t left = ceilIn(uc - hw, width), right = ceilIn(uc + hw, width);
    x0[u] = left;
    x1[u] = valid ? right : left;  // empty unless valid
    y0[u] = ceilIn(vc - hh, height);
    y1[u] = ceilIn(vc + hh, height);
    const float raw_clamped = raw_f < 1.0f ? 1.0f : (raw_f > 65535.0f ? 65535.0f : raw_f);
    raw[u] = int32_t(raw_clamped);
  }
}

// Footprints are 1-3 pixels a side: the vectorised form of these loops (this file is built with
// -O3 for projectRow) spends far more in its set-up than it saves. GCC only (clang does not
// vectorise it this way).
#if defined(__GNUC__) && !defined(__clang__)
__attribute__((optimize("no-tree-vectorize")))
#endif
void DepthRegistration::splatRow(cv::Mat& out) {
  uint16_t* const out_base = out.ptr<uint16_t>(0);
  const std::size_t out_stride = out.step1();
  for (int u = 0; u < depth_width_; ++u) {
    const int32_t x0 = x0_[u], x1 = x1_[u];
    if (x0 >= x1) continue;
    const uint16_t raw = uint16_t(raw_[u]);
    for (int32_t y = y0_[u]; y < y1_[u]; ++y) {
      uint16_t* out_row = out_base + std::size_t(y) * out_stride;
      for (int32_t x = x0; x < x1; ++x) {
        // z-buffer on raw values, 0 = empty: (value - 1) wraps 0 to the largest. Branch-free:
        // which sample wins is as unpredictable as the surfaces.
        out_row[x] = uint16_t(std::min(uint16_t(raw - 1), uint16_t(out_row[x] - 1)) + 1);
      }
    }
  }
}

}  // namespace plumb

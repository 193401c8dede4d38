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

// Normalised colour coordinates -> distorted colour pixel (PinholeCamera::distortPoint in float).
struct ColourLens {
  float fx, fy, cx, cy, k1, k2, p1, p2, k3;
  explicit ColourLens(const PinholeCamera& c)
      : fx(float(c.fx)), fy(float(c.fy)), cx(float(c.cx)), cy(float(c.cy)), k1(float(c.k1)), k2(float(c.k2)),
        p1(float(c.p1)), p2(float(c.p2)), k3(float(c.k3)) {}
  template <bool kDistortion>
  void toPixel(float x, float y, float* u, float* v) const {
    if (kDistortion) {
      const float r2 = x * x + y * y;
      const float radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
      const float xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
      const float yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
      x = xd;
      y = yd;
    }
    *u = fx * x + cx;
    *v = fy * y + cy;
  }
};

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
  pixels_.resize(std::size_t(d.width) * d.height);
  for (int v = 0; v < d.height; ++v) {
    for (int u = 0; u < d.width; ++u) {
      DepthPixel& p = pixels_[std::size_t(v) * d.width + u];
      const Eigen::Vector3d ray = rayOf(u, v);
      p.ray_x = float(ray.x());
      p.ray_y = float(ray.y());
      p.ray_z = float(ray.z());
      double u0 = 1e30, u1 = -1e30, v0 = 1e30, v1 = -1e30;
      for (const double du : {-0.5, 0.5}) {
        for (const double dv : {-0.5, 0.5}) {
          const Eigen::Vector3d corner = rayOf(u + du, v + dv);
          const Eigen::Vector2d px = corner.z() > 0 ? colourPixelOf(corner) : Eigen::Vector2d(0, 0);
          u0 = std::min(u0, px.x());
          u1 = std::max(u1, px.x());
          v0 = std::min(v0, px.y());
          v1 = std::max(v1, px.y());
        }
      }
      p.half_w = float(std::min(0.5 * (u1 - u0) + kFootprintGrowthPx, 0.5 * kMaxFootprintPx));
      p.half_h = float(std::min(0.5 * (v1 - v0) + kFootprintGrowthPx, 0.5 * kMaxFootprintPx));
    }
  }
}

bool DepthRegistration::registerInto(const cv::Mat& depth, double depth_factor, cv::Mat& out) const {
  if (!active_ || depth.type() != CV_16UC1 || depth.cols != depth_width_ || depth.rows != depth_height_ ||
      !(depth_factor > 0)) {
    return false;
  }
  out.create(colour_.height, colour_.width, CV_16UC1);  // no-op once sized
  if (colour_.hasDistortion()) {
    warp<true>(depth, depth_factor, out);
  } else {
    warp<false>(depth, depth_factor, out);
  }
  return true;
}

template <bool kColourDistortion>
void DepthRegistration::warp(const cv::Mat& depth, double depth_factor, cv::Mat& out) const {
  for (int r = 0; r < out.rows; ++r) std::memset(out.ptr<uint16_t>(r), 0, std::size_t(out.cols) * sizeof(uint16_t));
  const ColourLens lens(colour_);
  const float to_metres = float(1.0 / depth_factor);
  const float to_raw = float(depth_factor);
  const int width = out.cols, height = out.rows;
  for (int v = 0; v < depth_height_; ++v) {
    const uint16_t* in_row = depth.ptr<uint16_t>(v);
    const DepthPixel* pixel_row = pixels_.data() + std::size_t(v) * depth_width_;
    for (int u = 0; u < depth_width_; ++u) {
      if (in_row[u] == 0) continue;
      const DepthPixel& p = pixel_row[u];
      const float z_depth = float(in_row[u]) * to_metres;
      const float Z = z_depth * p.ray_z + tz_;
      if (Z < kMinColourZ) continue;
      const float raw_f = Z * to_raw + 0.5f;
      if (raw_f >= 65536.0f) continue;  // not representable in the colour image: no reading
      const uint16_t raw = uint16_t(std::max(1.0f, raw_f));
      const float inv_Z = 1.0f / Z;
      float uc, vc;
      lens.toPixel<kColourDistortion>((z_depth * p.ray_x + tx_) * inv_Z, (z_depth * p.ray_y + ty_) * inv_Z, &uc, &vc);
      // Footprint at this depth; the colour pixels whose centres it holds (half-open intervals, so
      // neighbouring footprints of one surface neither overlap nor leave a gap).
      const float scale = 1.0f - tz_ * inv_Z;
      const float hw = p.half_w * scale, hh = p.half_h * scale;
      const float left = uc - hw, top = vc - hh;
      if (!(left < float(width) && top < float(height) && uc + hw > 0 && vc + hh > 0)) continue;
      const int x0 = std::max(0, int(std::ceil(left)));
      const int x1 = std::min({width, int(std::ceil(uc + hw)), x0 + kMaxFootprintPx});
      const int y0 = std::max(0, int(std::ceil(top)));
      const int y1 = std::min({height, int(std::ceil(vc + hh)), y0 + kMaxFootprintPx});
      for (int y = y0; y < y1; ++y) {
        uint16_t* out_row = out.ptr<uint16_t>(y);
        for (int x = x0; x < x1; ++x) {
          // z-buffer on raw values, 0 = empty: (value - 1) wraps 0 to the largest.
          if (uint16_t(raw - 1) < uint16_t(out_row[x] - 1)) out_row[x] = raw;
        }
      }
    }
  }
}

}  // namespace plumb

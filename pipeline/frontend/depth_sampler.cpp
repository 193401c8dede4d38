#include "pipeline/frontend/depth_sampler.h"

#include <algorithm>
#include <cmath>

#include "pipeline/frontend/line_fit3d.h"
#include "pipeline/frontend/round_half_away.h"
#include "solver/noise_model.h"

namespace plumb {

DepthSampler::DepthSampler(const PinholeCamera& camera, const ExtractorOptions& options)
    : camera_(camera), options_(options) {
  intrinsics_.fx = camera.fx;
  intrinsics_.fy = camera.fy;
  intrinsics_.cx = camera.cx;
  intrinsics_.cy = camera.cy;
  intrinsics_.bf = camera.fx * camera.baseline_m;
}

float DepthSampler::depthAt(const cv::Mat& depth_raw, double depth_factor, float xf, float yf,
                            bool prefer_near_surface) const {
  const float inv_factor = static_cast<float>(1.0 / depth_factor);
  const float min_d = options_.min_depth_m, max_d = options_.max_depth_m;
  auto read = [&](int u, int v) -> float {
    if (u < 0 || v < 0 || u >= depth_raw.cols || v >= depth_raw.rows) return 0.f;
    const float d = depth_raw.at<uint16_t>(v, u) * inv_factor;
    return (d >= min_d && d <= max_d) ? d : 0.f;
  };
  // Depth jump that separates two surfaces: a few sigmas, at least 2 cm.
  auto discontinuity = [&](float d) { return std::max(0.02f, 4 * static_cast<float>(depthSigma(options_.noise, d))); };
  const int x0 = static_cast<int>(std::floor(xf)), y0 = static_cast<int>(std::floor(yf));
  const float d00 = read(x0, y0), d10 = read(x0 + 1, y0), d01 = read(x0, y0 + 1), d11 = read(x0 + 1, y0 + 1);
  const float lo = std::min(std::min(d00, d10), std::min(d01, d11));
  const float hi = std::max(std::max(d00, d10), std::max(d01, d11));
  if (lo > 0 && hi - lo < discontinuity(lo)) {
    const float ax = xf - x0, ay = yf - y0;
    return (1 - ay) * ((1 - ax) * d00 + ax * d10) + ay * ((1 - ax) * d01 + ax * d11);
  }
  const int x = static_cast<int>(roundHalfAwayFromZero(xf)), y = static_cast<int>(roundHalfAwayFromZero(yf));
  const float centre = read(x, y);
  if (!prefer_near_surface) return centre;
  // Nearest valid reading in the (2r+1)^2 window, 0 if none.
  auto nearest = [&](int r) {
    float best = 0;
    for (int v = y - r; v <= y + r; ++v) {
      for (int u = x - r; u <= x + r; ++u) {
        const float d = read(u, v);
        if (d > 0 && (best == 0 || d < best)) best = d;
      }
    }
    return best;
  };
  if (options_.depth_edge_radius_px > 0) {
    const float near = nearest(options_.depth_edge_radius_px);
    // On an occluding edge the centre pixel may read the background: if the window holds a
    // clearly nearer surface (beyond a few depth sigmas), that surface is the one the edge belongs to.
    if (centre == 0) {
      if (near > 0) return near;
    } else {
      return (centre - near > discontinuity(near)) ? near : centre;
    }
  } else if (centre > 0) {
    return centre;
  }
  // A hole: the nearest reading in a widening window.
  for (int r = std::max(1, options_.depth_edge_radius_px + 1); r <= options_.depth_hole_radius_px; ++r) {
    const float d = nearest(r);
    if (d > 0) return d;
  }
  return 0.f;
}

bool DepthSampler::onDepthEdge(const cv::Mat& depth_raw, double depth_factor, const Eigen::Vector2f& px) const {
  const int r = options_.keypoint_edge_radius_px;
  if (r <= 0) return false;
  const int x = static_cast<int>(roundHalfAwayFromZero(px.x())), y = static_cast<int>(roundHalfAwayFromZero(px.y()));
  const int x0 = std::max(0, x - r), x1 = std::min(depth_raw.cols - 1, x + r);
  const int y0 = std::max(0, y - r), y1 = std::min(depth_raw.rows - 1, y + r);
  int lo = 1 << 20, hi = 0;
  for (int v = y0; v <= y1; ++v) {
    const uint16_t* row = depth_raw.ptr<uint16_t>(v);
    for (int u = x0; u <= x1; ++u) {
      if (row[u] == 0) continue;  // holes are not surfaces
      lo = std::min<int>(lo, row[u]);
      hi = std::max<int>(hi, row[u]);
    }
  }
  if (hi == 0) return false;
  const float near = static_cast<float>(lo / depth_factor), far = static_cast<float>(hi / depth_factor);
  return far - near > std::max(0.02f, 4 * static_cast<float>(depthSigma(options_.noise, near)));
}

void DepthSampler::attachDepth(const cv::Mat& depth_raw, double depth_factor, FrameFeatures& features) const {
  const bool has_depth = !depth_raw.empty() && depth_raw.type() == CV_16UC1 && depth_factor > 0;
  const float bf = static_cast<float>(intrinsics_.bf);
  for (KeypointObservation& kp : features.keypoints) {
    kp.depth_m = 0;
    kp.u_right = -1;
    kp.info_uvr.setZero();
    if (!has_depth) continue;
    const float d = depthAt(depth_raw, depth_factor, kp.px.x(), kp.px.y(), false);
    if (d <= 0 || onDepthEdge(depth_raw, depth_factor, kp.px)) continue;
    kp.depth_m = d;
    kp.u_right = kp.px_undist.x() - bf / d;
    kp.P_cam = camera_.unproject(kp.px_undist.x(), kp.px_undist.y(), d).cast<float>();
    kp.info_uvr = stereoPointInformation(options_.noise, intrinsics_, kp.octave, d).cast<float>();
  }
  for (LineObservation& line : features.lines) {
    line.num_samples = 0;
    line.has_3d = false;
    if (has_depth && options_.line_samples > 0) sampleLine(depth_raw, depth_factor, line);
  }
}

void DepthSampler::sampleLine(const cv::Mat& depth_raw, double depth_factor, LineObservation& line) const {
  const int n = std::min<int>(options_.line_samples, kMaxLineSamples);
  const float margin = std::clamp(options_.sample_end_margin, 0.f, 0.45f);
  std::array<Eigen::Vector2f, kMaxLineSamples> px{};
  std::array<Eigen::Vector3f, kMaxLineSamples> P{};
  std::array<float, kMaxLineSamples> threshold{}, depth{};
  int valid = 0;
  for (int k = 0; k < n; ++k) {
    const float t = n == 1 ? 0.5f : margin + (1 - 2 * margin) * k / static_cast<float>(n - 1);
    const Eigen::Vector2f uv = line.start_px + t * (line.end_px - line.start_px);
    const Eigen::Vector2d raw = camera_.distortPoint(uv.x(), uv.y());
    const float d = depthAt(depth_raw, depth_factor, static_cast<float>(raw.x()), static_cast<float>(raw.y()), true);
    if (d <= 0) continue;
    px[valid] = uv;
    depth[valid] = d;
    P[valid] = camera_.unproject(uv.x(), uv.y(), d).cast<float>();
    threshold[valid] = std::max(options_.fit_min_threshold_m,
                                options_.fit_sigma_multiplier * static_cast<float>(depthSigma(options_.noise, d)));
    ++valid;
  }
  const int min_inliers = std::max(2, options_.min_line_inliers);
  if (valid < min_inliers) return;
  const Line3dFit fit = fitLine3dRobust(P.data(), threshold.data(), valid, min_inliers);
  if (!fit.ok) return;
  int kept = 0;
  for (int i = 0; i < valid; ++i) {
    if (!fit.inlier[i]) continue;
    line.sample_px[kept] = px[i];
    line.sample_P_cam[kept] = P[i];
    line.sample_cov[kept] = backProjectedPointCovariance(options_.noise, intrinsics_, px[i].x(), px[i].y(),
                                                         depth[i], line.octave).cast<float>();
    ++kept;
  }
  line.num_samples = static_cast<uint8_t>(kept);
  line.has_3d = true;
  line.line_point_cam = fit.point;
  // Orient the 3D direction like the 2D segment (first kept sample towards the last).
  const Eigen::Vector3f span = line.sample_P_cam[kept - 1] - line.sample_P_cam[0];
  line.line_dir_cam = span.dot(fit.direction) < 0 ? Eigen::Vector3f(-fit.direction) : fit.direction;
}

}  // namespace plumb

#pragma once
// PinholeCamera: intrinsics, Brown-Conrady distortion (k1 k2 p1 p2 k3, OpenCV order), image size,
// depth scale and the virtual stereo baseline used by the RGB-D point observation [u, v, u_r]
// (u_r = u - fx * b / d, paper section V-D).
//
// fy may be negative (ICL-NUIM's TUM-format ground truth needs fy = -480): nothing here assumes
// fx, fy > 0, only that they are finite and non-zero.
//
// Features are detected on the raw (distorted) image; their coordinates are undistorted once
// (undistortPoint) and everything downstream (matching by projection, the solver) works in the
// ideal pinhole model.
#include <cmath>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "sensor/depth_camera.h"

namespace plumb {

// Largest image side plumb accepts (pixels): 8K. Everything that allocates per image (slots,
// pyramids, decoders) is sized from a camera inside this bound. (Tracking has its own minimum:
// OdometrySystem::create.)
constexpr int kMaxImageSide = 8192;

struct PinholeCamera {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
  int width = 640, height = 480;
  // Raw depth units per metre (TUM: 5000, Kinect mm images: 1000).
  double depth_factor = 5000.0;
  // Virtual baseline in metres for u_r = u - fx*b/d (ORB-SLAM2's RGB-D convention: 0.08 m).
  double baseline_m = 0.08;
  // Rolling shutter: seconds from the first to the last image row's exposure; 0 = global shutter.
  // The tracker moves features to the middle row's time (pipeline/odometry/tracker_rolling_shutter.h).
  double rolling_shutter_readout_s = 0.0;
  // Depth from a separate depth camera, not registered to this (colour) camera: its intrinsics,
  // size and T_colour_depth. Empty (every preset): depth images are registered, camera-sized.
  // Sources deliver such depth as the depth camera sees it (depthWidth() x depthHeight()); the
  // pipeline registers it into this camera before extraction (docs/FRONTEND.md).
  std::optional<DepthCamera> depth_camera;

  bool depthRegistered() const { return !depth_camera.has_value(); }
  // Size of the depth images a source delivers.
  int depthWidth() const { return depth_camera ? depth_camera->width : width; }
  int depthHeight() const { return depth_camera ? depth_camera->height : height; }

  bool hasDistortion() const { return k1 != 0 || k2 != 0 || p1 != 0 || p2 != 0 || k3 != 0; }

  // Ideal pinhole projection of a point in the camera frame (z > 0 expected).
  Eigen::Vector2d project(const Eigen::Vector3d& P_cam) const {
    return {fx * P_cam.x() / P_cam.z() + cx, fy * P_cam.y() / P_cam.z() + cy};
  }
  // Back-projection of an undistorted pixel at depth d (metres, along the optical axis).
  Eigen::Vector3d unproject(double u, double v, double depth_m) const {
    return {(u - cx) / fx * depth_m, (v - cy) / fy * depth_m, depth_m};
  }

  // Distorted pixel -> undistorted (ideal) pixel, by fixed-point iteration on the normalised
  // coordinates (converges in a handful of steps for the distortion of Kinect-class lenses).
  Eigen::Vector2d undistortPoint(double u, double v) const {
    if (!hasDistortion()) return {u, v};
    const double xd = (u - cx) / fx, yd = (v - cy) / fy;
    double x = xd, y = yd;
    for (int it = 0; it < 10; ++it) {
      const double r2 = x * x + y * y;
      const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
      const double dx = 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
      const double dy = p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
      x = (xd - dx) / radial;
      y = (yd - dy) / radial;
    }
    return {fx * x + cx, fy * y + cy};
  }
  // Ideal pixel -> distorted pixel (the forward lens model).
  Eigen::Vector2d distortPoint(double u, double v) const {
    if (!hasDistortion()) return {u, v};
    const double x = (u - cx) / fx, y = (v - cy) / fy;
    const double r2 = x * x + y * y;
    const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const double xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
    const double yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
    return {fx * xd + cx, fy * yd + cy};
  }

  bool inImage(double u, double v, double border = 0) const {
    return u >= border && v >= border && u < width - border && v < height - border;
  }

  // Empty string when valid; otherwise what is wrong (NaN, zero focal length, bad size...).
  std::string validate() const {
    auto finite = [](double x) { return std::isfinite(x); };
    if (!finite(fx) || !finite(fy) || !finite(cx) || !finite(cy)) return "intrinsics are not finite";
    if (!finite(k1) || !finite(k2) || !finite(p1) || !finite(p2) || !finite(k3))
      return "distortion coefficients are not finite";
    if (fx == 0 || fy == 0) return "focal length is zero";
    if (width <= 0 || height <= 0) return "image size must be positive";
    // Bounds checked before anything is allocated for an image (a 100000-pixel-wide "camera" is a
    // typo or a hostile file, not a sensor): docs/DATA_FORMATS.md.
    if (width > kMaxImageSide || height > kMaxImageSide)
      return "image size " + std::to_string(width) + "x" + std::to_string(height) + " exceeds " +
             std::to_string(kMaxImageSide) + " pixels per side";
    if (!finite(depth_factor) || depth_factor <= 0) return "depth factor must be positive";
    if (!finite(baseline_m) || baseline_m <= 0) return "baseline must be positive";
    if (!finite(rolling_shutter_readout_s) || rolling_shutter_readout_s < 0)
      return "rolling_shutter_readout must be >= 0";
    if (depth_camera) return validateDepthCamera();
    return "";
  }

 private:
  // The depth camera on its own (depth_camera.h), then one joint check: the centre of the depth
  // camera's view at 2 m must land in the colour image, or the transform points the wrong way
  // (colour-to-depth given for depth-to-colour) or belongs to another camera.
  std::string validateDepthCamera() const {
    const std::string problem = depth_camera->validate(kMaxImageSide);
    if (!problem.empty()) return problem;
    const DepthCamera& d = *depth_camera;
    const Eigen::Vector3d P_depth((d.width / 2.0 - d.cx) / d.fx * 2.0, (d.height / 2.0 - d.cy) / d.fy * 2.0, 2.0);
    const Eigen::Vector3d P_colour = d.T_colour_depth() * P_depth;
    const Eigen::Vector2d px = P_colour.z() > 0 ? project(P_colour) : Eigen::Vector2d(-1e9, -1e9);
    if (!inImage(px.x(), px.y())) {
      return "the centre of the depth camera's view (at 2 m) falls outside the colour image, at (" +
             std::to_string(px.x()) + ", " + std::to_string(px.y()) +
             "): is depth_to_colour the colour-to-depth transform, or another camera's?";
    }
    return "";
  }
};

// The lens of a depth camera alone (intrinsics, distortion, size) as a PinholeCamera, for its
// projection and undistortion; the other fields keep their defaults.
inline PinholeCamera depthCameraLens(const DepthCamera& d) {
  PinholeCamera lens;
  lens.fx = d.fx;
  lens.fy = d.fy;
  lens.cx = d.cx;
  lens.cy = d.cy;
  lens.k1 = d.k1;
  lens.k2 = d.k2;
  lens.p1 = d.p1;
  lens.p2 = d.p2;
  lens.k3 = d.k3;
  lens.width = d.width;
  lens.height = d.height;
  return lens;
}

}  // namespace plumb

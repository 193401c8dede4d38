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
#include <cstdio>
#include <optional>
#include <string>
#include <tuple>

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

  // Empty string when valid; otherwise what is wrong (NaN, zero focal length, bad size...). Beyond
  // "a number", each value must be plausible for a real camera (kCameraBounds below): a principal
  // point off the image, a focal length of 1e300 or 1e-300 pixels, a distortion of 1e6 or a readout
  // of 1e9 s is a typo or a hostile file, and accepting it tracks "ok" frames into nonsense.
  std::string validate() const;

 private:
  // The depth camera (depth_camera.h, plus the distortion bounds below), then one joint check:
  // the centre of the depth camera's view at 2 m must land in the colour image, or the transform
  // points the wrong way (colour-to-depth given for depth-to-colour) or belongs to another camera.
  std::string validateDepthCamera() const;
};

// Plausibility bounds of PinholeCamera::validate (docs/DATA_FORMATS.md "Camera").
struct CameraBounds {
  // |fx| / width and |fy| / height: a horizontal (vertical) field of view between ~0.6 and ~170 deg.
  double min_focal_per_side = 0.04, max_focal_per_side = 100.0;
  double max_radial = 100.0;       // |k1|, |k2|, |k3|
  double max_tangential = 1.0;     // |p1|, |p2|
  double min_depth_factor = 1.0, max_depth_factor = 1e5;  // raw units per metre (TUM 5000, mm 1000)
  double max_baseline_m = 10.0;
  double max_readout_s = 1.0;      // rolling-shutter readout: below a frame period of 1 fps
};
inline constexpr CameraBounds kCameraBounds{};

inline std::string PinholeCamera::validate() const {
  auto finite = [](double x) { return std::isfinite(x); };
  auto text = [](double x) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%g", x);
    return std::string(buffer);
  };
  const CameraBounds& b = kCameraBounds;
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
  if (!(cx >= 0 && cx <= width && cy >= 0 && cy <= height))
    return "principal point (" + text(cx) + ", " + text(cy) + ") is outside the " + std::to_string(width) + "x" +
           std::to_string(height) + " image";
  for (const auto& [name, f, side] : {std::tuple<const char*, double, int>{"fx", fx, width}, {"fy", fy, height}}) {
    const double ratio = std::abs(f) / side;
    if (ratio < b.min_focal_per_side || ratio > b.max_focal_per_side)
      return std::string("focal length ") + name + " " + text(f) + " is implausible for a " + std::to_string(side) +
             "-pixel side (|" + name + "| must be within " + text(b.min_focal_per_side * side) + ".." +
             text(b.max_focal_per_side * side) + " pixels)";
  }
  if (std::abs(k1) > b.max_radial || std::abs(k2) > b.max_radial || std::abs(k3) > b.max_radial)
    return "radial distortion k1 k2 k3 (" + text(k1) + " " + text(k2) + " " + text(k3) + ") beyond +-" +
           text(b.max_radial);
  if (std::abs(p1) > b.max_tangential || std::abs(p2) > b.max_tangential)
    return "tangential distortion p1 p2 (" + text(p1) + " " + text(p2) + ") beyond +-" + text(b.max_tangential);
  if (!finite(depth_factor) || depth_factor <= 0) return "depth factor must be positive";
  if (depth_factor < b.min_depth_factor || depth_factor > b.max_depth_factor)
    return "depth factor " + text(depth_factor) + " outside " + text(b.min_depth_factor) + ".." +
           text(b.max_depth_factor) + " raw units per metre";
  if (!finite(baseline_m) || baseline_m <= 0) return "baseline must be positive";
  if (baseline_m > b.max_baseline_m) return "baseline " + text(baseline_m) + " m beyond " + text(b.max_baseline_m) + " m";
  if (!finite(rolling_shutter_readout_s) || rolling_shutter_readout_s < 0)
    return "rolling_shutter_readout must be >= 0";
  if (rolling_shutter_readout_s > b.max_readout_s)
    return "rolling_shutter_readout " + text(rolling_shutter_readout_s) + " s beyond " + text(b.max_readout_s) + " s";
  if (depth_camera) return validateDepthCamera();
  return "";
}

inline std::string PinholeCamera::validateDepthCamera() const {
  const std::string problem = depth_camera->validate(kMaxImageSide);
  if (!problem.empty()) return problem;
  const DepthCamera& d = *depth_camera;
  const CameraBounds& b = kCameraBounds;
  if (std::abs(d.k1) > b.max_radial || std::abs(d.k2) > b.max_radial || std::abs(d.k3) > b.max_radial ||
      std::abs(d.p1) > b.max_tangential || std::abs(d.p2) > b.max_tangential)
    return "depth camera distortion beyond the colour camera's bounds (|k| <= " + std::to_string(int(b.max_radial)) +
           ", |p| <= " + std::to_string(int(b.max_tangential)) + ")";
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

#pragma once
// DepthCamera: the geometry of a depth camera that is NOT registered to the colour camera (UVC
// depth cameras: RealSense, Orbbec, a Kinect v1 without hardware registration). Its images are
// registered into the colour camera once per frame before features are extracted
// (pipeline/frontend/depth_registration.h); PinholeCamera::depth_camera holds it, empty when
// depth is already registered (every preset).
//
// T_colour_depth maps depth-camera points into the colour camera: P_colour = R(q) P_depth + t,
// metres. The quaternion is kept exactly as given (a camera file round-trips bit for bit) and
// normalised when used. Format and bounds: docs/DATA_FORMATS.md "Unregistered depth".
#include <cmath>
#include <cstdio>
#include <string>

#include <Eigen/Geometry>

namespace plumb {

struct DepthCamera {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;  // Brown-Conrady, OpenCV order, as the colour camera
  int width = 0, height = 0;
  double qx = 0, qy = 0, qz = 0, qw = 1;  // rotation of T_colour_depth
  double tx = 0, ty = 0, tz = 0;          // translation of T_colour_depth, metres

  // Plausibility bounds: a depth camera beside a colour camera in one housing. Beyond them a file
  // is far more likely wrong (millimetres for metres, the inverse transform, a typo) than right.
  static constexpr double kMaxTranslationM = 0.3;
  static constexpr double kMaxRotationDeg = 15.0;
  static constexpr double kMinFieldOfViewDeg = 2.0, kMaxFieldOfViewDeg = 170.0;
  static constexpr double kMaxQuaternionNormError = 0.01;

  bool hasDistortion() const { return k1 != 0 || k2 != 0 || p1 != 0 || p2 != 0 || k3 != 0; }
  double quaternionNorm() const { return std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw); }

  Eigen::Isometry3d T_colour_depth() const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix();
    T.translation() = Eigen::Vector3d(tx, ty, tz);
    return T;
  }
  double rotationDeg() const {
    return Eigen::AngleAxisd(T_colour_depth().linear()).angle() * 180.0 / 3.14159265358979323846;
  }

  // Empty when plausible; otherwise one message per violated bound, naming the camera file key.
  // `max_image_side` is the colour camera's bound (sensor/camera.h kMaxImageSide).
  std::string validate(int max_image_side) const {
    auto finite = [](double x) { return std::isfinite(x); };
    char buf[240];
    if (!finite(fx) || !finite(fy) || !finite(cx) || !finite(cy)) return "depth camera intrinsics are not finite";
    if (!finite(k1) || !finite(k2) || !finite(p1) || !finite(p2) || !finite(k3))
      return "depth camera distortion coefficients are not finite";
    if (!finite(qx) || !finite(qy) || !finite(qz) || !finite(qw) || !finite(tx) || !finite(ty) || !finite(tz))
      return "depth_to_colour transform is not finite";
    if (width <= 0 || height <= 0) return "depth_width and depth_height must be positive";
    if (width > max_image_side || height > max_image_side) {
      std::snprintf(buf, sizeof(buf), "depth image size %dx%d exceeds %d pixels per side", width, height,
                    max_image_side);
      return buf;
    }
    if (fx == 0 || fy == 0) return "depth camera focal length is zero";
    // Field of view 2 atan(size / 2|f|): a focal length in the wrong unit (mm) or for another
    // image size lands far outside what depth cameras see.
    const double fov_x = 2 * std::atan(width / (2 * std::abs(fx))) * 180 / 3.14159265358979323846;
    const double fov_y = 2 * std::atan(height / (2 * std::abs(fy))) * 180 / 3.14159265358979323846;
    if (fov_x < kMinFieldOfViewDeg || fov_x > kMaxFieldOfViewDeg || fov_y < kMinFieldOfViewDeg ||
        fov_y > kMaxFieldOfViewDeg) {
      std::snprintf(buf, sizeof(buf),
                    "depth_fx/depth_fy give a %.1f x %.1f degree field of view for a %dx%d depth image; "
                    "depth cameras see %.0f..%.0f degrees (focal length in pixels, for this image size?)",
                    fov_x, fov_y, width, height, kMinFieldOfViewDeg, kMaxFieldOfViewDeg);
      return buf;
    }
    if (cx < 0 || cx > width || cy < 0 || cy > height) {
      std::snprintf(buf, sizeof(buf), "depth principal point (%.1f, %.1f) lies outside the %dx%d depth image", cx, cy,
                    width, height);
      return buf;
    }
    const double norm = quaternionNorm();
    if (std::abs(norm - 1) > kMaxQuaternionNormError) {
      std::snprintf(buf, sizeof(buf),
                    "depth_to_colour quaternion (qx qy qz qw) has norm %.4g; it must be a unit quaternion", norm);
      return buf;
    }
    const double angle = rotationDeg();
    if (angle > kMaxRotationDeg) {
      std::snprintf(buf, sizeof(buf),
                    "depth_to_colour rotation is %.1f degrees; the depth and colour cameras of an RGB-D camera look "
                    "the same way (at most %.0f degrees accepted)",
                    angle, kMaxRotationDeg);
      return buf;
    }
    const double t = std::sqrt(tx * tx + ty * ty + tz * tz);
    if (t > kMaxTranslationM) {
      std::snprintf(buf, sizeof(buf),
                    "depth_to_colour translation is %.4g m long; the two cameras of an RGB-D camera are centimetres "
                    "apart (at most %.1f m accepted; give metres, not millimetres)",
                    t, kMaxTranslationM);
      return buf;
    }
    return "";
  }
};

}  // namespace plumb

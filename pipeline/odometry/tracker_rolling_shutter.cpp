#include "pipeline/odometry/tracker_rolling_shutter.h"

#include <cmath>

#include "solver/se3.h"

namespace plumb {
namespace {

// Depth given to features without one: only the direction matters for a rotation, and the
// translation part of the correction (millimetres over a readout) is negligible at room scale.
constexpr double kNominalDepthM = 2.0;

// exp(s xi) applied to points for one twist xi = [rho; phi] and many scales s (one per image row
// time), without forming the 4x4 transform each time: with K = [s phi]x and theta = |s phi|,
//   exp(s xi) X = X + a K X + b K^2 X + s rho + b s K rho + c s K^2 rho
// (a = sin(theta) / theta, b = (1 - cos(theta)) / theta^2, c = (theta - sin(theta)) / theta^3, the
// expSE3 of solver/se3.h), where K rho = s (phi x rho) and K^2 rho = s^2 phi x (phi x rho) are
// formed once. The angles of a readout are small (|phi| dt: ~0.01 rad), so a, b and c come from
// their Taylor series up to theta^6, whose first omitted term is below double precision (1e-16
// relative) for theta < 0.05; above that from sin and cos, as expSE3 does.
class ScaledTwistExp {
 public:
  explicit ScaledTwistExp(const Vector6d& xi)
      : rho_(xi.head<3>()), phi_(xi.tail<3>()), phi_x_rho_(phi_.cross(rho_)), phi_x_phi_x_rho_(phi_.cross(phi_x_rho_)),
        theta2_per_s2_(phi_.squaredNorm()) {}

  Eigen::Vector3d apply(double s, const Eigen::Vector3d& X) const {
    double a, b, c;
    coefficients(s, &a, &b, &c);
    const Eigen::Vector3d phi = s * phi_;
    const Eigen::Vector3d KX = phi.cross(X);
    return X + a * KX + b * phi.cross(KX) + s * rho_ + (b * s * s) * phi_x_rho_ + (c * s * s * s) * phi_x_phi_x_rho_;
  }
  Eigen::Vector3d rotate(double s, const Eigen::Vector3d& d) const {
    double a, b, c;
    coefficients(s, &a, &b, &c);
    const Eigen::Vector3d phi = s * phi_;
    const Eigen::Vector3d Kd = phi.cross(d);
    return d + a * Kd + b * phi.cross(Kd);
  }

 private:
  void coefficients(double s, double* a, double* b, double* c) const {
    const double t2 = s * s * theta2_per_s2_;
    if (t2 < 0.05 * 0.05) {
      const double t4 = t2 * t2, t6 = t4 * t2;
      *a = 1.0 - t2 / 6.0 + t4 / 120.0 - t6 / 5040.0;
      *b = 0.5 - t2 / 24.0 + t4 / 720.0 - t6 / 40320.0;
      *c = 1.0 / 6.0 - t2 / 120.0 + t4 / 5040.0 - t6 / 362880.0;
      return;
    }
    const double t = std::sqrt(t2), sin_t = std::sin(t), cos_t = std::cos(t);
    *a = sin_t / t;
    *b = (1.0 - cos_t) / t2;
    *c = (t - sin_t) / (t2 * t);
  }

  Eigen::Vector3d rho_, phi_, phi_x_rho_, phi_x_phi_x_rho_;
  double theta2_per_s2_;
};

}  // namespace

void compensateRollingShutter(const PinholeCamera& camera, double readout_s, const Vector6d& twist_per_s,
                              FrameFeatures* frame) {
  if (!(readout_s > 0)) return;
  const double seconds_per_row = readout_s / double(camera.height);
  // X_mid = exp(-dt(row) xi) X_row.
  const ScaledTwistExp motion(twist_per_s);
  auto to_middle_row = [&](double row, const Eigen::Vector3d& X_row) -> Eigen::Vector3d {
    const double dt = (row - camera.cy) * seconds_per_row;
    return motion.apply(-dt, X_row);
  };
  const double bf = camera.fx * camera.baseline_m;

  for (KeypointObservation& kp : frame->keypoints) {
    const double row = kp.px.y();  // the sensor row it was read on (raw image)
    const bool has_depth = kp.depth_m > 0;
    const Eigen::Vector3d X_row =
        has_depth ? Eigen::Vector3d(kp.P_cam.cast<double>())
                  : camera.unproject(kp.px_undist.x(), kp.px_undist.y(), kNominalDepthM);
    const Eigen::Vector3d X = to_middle_row(row, X_row);
    if (!(X.z() > 0)) continue;
    kp.px_undist = camera.project(X).cast<float>();
    if (has_depth) {
      kp.P_cam = X.cast<float>();
      kp.depth_m = float(X.z());
      kp.u_right = float(double(kp.px_undist.x()) - bf / X.z());
    }
  }

  auto raw_row = [&camera](const Eigen::Vector2f& px_undist) {
    return camera.distortPoint(px_undist.x(), px_undist.y()).y();
  };
  for (LineObservation& line : frame->lines) {
    const double start_row = raw_row(line.start_px), end_row = raw_row(line.end_px);
    const Eigen::Vector3d S =
        to_middle_row(start_row, camera.unproject(line.start_px.x(), line.start_px.y(), kNominalDepthM));
    const Eigen::Vector3d E =
        to_middle_row(end_row, camera.unproject(line.end_px.x(), line.end_px.y(), kNominalDepthM));
    if (!(S.z() > 0) || !(E.z() > 0)) continue;
    line.start_px = camera.project(S).cast<float>();
    line.end_px = camera.project(E).cast<float>();
    const Eigen::Vector3d l = Eigen::Vector3d(line.start_px.x(), line.start_px.y(), 1.0)
                                  .cross(Eigen::Vector3d(line.end_px.x(), line.end_px.y(), 1.0));
    const double norm = std::hypot(l.x(), l.y());
    if (norm > 0) line.l = l / norm;
    for (int s = 0; s < line.num_samples; ++s) {
      const Eigen::Vector3d X = to_middle_row(raw_row(line.sample_px[s]), line.sample_P_cam[s].cast<double>());
      if (!(X.z() > 0)) continue;
      line.sample_P_cam[s] = X.cast<float>();
      line.sample_px[s] = camera.project(X).cast<float>();
    }
    if (line.has_3d) {
      // The fitted 3D line moves with the segment's middle row (the rows it spans differ by
      // less than the fit's resolution).
      const double dt = (0.5 * (start_row + end_row) - camera.cy) * seconds_per_row;
      line.line_point_cam = motion.apply(-dt, line.line_point_cam.cast<double>()).cast<float>();
      line.line_dir_cam = motion.rotate(-dt, line.line_dir_cam.cast<double>()).cast<float>();
    }
  }

  frame->keypoint_grid.build(int(frame->keypoints.size()),
                             [frame](int i) { return frame->keypoints[i].px_undist; });
}

}  // namespace plumb

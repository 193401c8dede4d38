#include "pipeline/odometry/tracker_rolling_shutter.h"

#include <cmath>

#include "solver/se3.h"

namespace plumb {
namespace {

// Depth given to features without one: only the direction matters for a rotation, and the
// translation part of the correction (millimetres over a readout) is negligible at room scale.
constexpr double kNominalDepthM = 2.0;

}  // namespace

void compensateRollingShutter(const PinholeCamera& camera, double readout_s, const Vector6d& twist_per_s,
                              FrameFeatures* frame) {
  if (!(readout_s > 0)) return;
  const double seconds_per_row = readout_s / double(camera.height);
  // X_mid = exp(-dt(row) xi) X_row.
  auto to_middle_row = [&](double row, const Eigen::Vector3d& X_row) -> Eigen::Vector3d {
    const double dt = (row - camera.cy) * seconds_per_row;
    return expSE3(-dt * twist_per_s) * X_row;
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
      const Eigen::Isometry3d T = expSE3(-dt * twist_per_s);
      line.line_point_cam = (T * line.line_point_cam.cast<double>()).cast<float>();
      line.line_dir_cam = (T.linear() * line.line_dir_cam.cast<double>()).cast<float>();
    }
  }

  frame->keypoint_grid.build(int(frame->keypoints.size()),
                             [frame](int i) { return frame->keypoints[i].px_undist; });
}

}  // namespace plumb

// Rolling-shutter compensation (pipeline/odometry/tracker_rolling_shutter.h): features observed by a
// rolling-shutter camera turning fast are moved to where a global-shutter camera at the middle
// row's time would have seen them.
//
// The observations are generated independently of the implementation: each world point is seen
// on the row r where it projects when the camera pose is that of row r's time (a fixed point,
// found by iteration), T_cam_world(t) = exp(t xi) T_cam_world(0) with t = (r - cy) * readout / H.
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "pipeline/odometry/tracker_rolling_shutter.h"
#include "solver/se3.h"

namespace plumb {
namespace {

PinholeCamera testCamera() {
  PinholeCamera c;
  c.fx = 520;
  c.fy = 515;
  c.cx = 320;
  c.cy = 240;
  c.width = 640;
  c.height = 480;
  c.rolling_shutter_readout_s = 0.03;
  return c;
}

// ~90 deg/s about the vertical axis plus some roll, pitch and translation (fr1/rpy-like).
Vector6d fastTwist() {
  Vector6d xi;
  xi << 0.10, -0.05, 0.02, 0.3, 1.55, -0.4;
  return xi;
}

// The point in the camera of the row it is read on (P_world in the middle-row camera frame).
Eigen::Vector3d seenOnItsRow(const PinholeCamera& camera, const Vector6d& xi, const Eigen::Vector3d& P) {
  Eigen::Vector3d X = P;
  for (int it = 0; it < 50; ++it) {
    const double row = camera.project(X).y();
    const double t = (row - camera.cy) * camera.rolling_shutter_readout_s / camera.height;
    X = expSE3(t * xi) * P;
  }
  return X;
}

KeypointObservation observe(const PinholeCamera& camera, const Eigen::Vector3d& X, bool with_depth) {
  KeypointObservation kp;
  kp.px_undist = camera.project(X).cast<float>();
  kp.px = kp.px_undist;  // no distortion: raw == undistorted
  if (with_depth) {
    kp.depth_m = float(X.z());
    kp.P_cam = X.cast<float>();
    kp.u_right = float(kp.px_undist.x() - camera.fx * camera.baseline_m / X.z());
  }
  return kp;
}

struct Scene {
  std::vector<Eigen::Vector3d> points;  // middle-row camera frame
  FrameFeatures frame;
};

Scene makeScene(const PinholeCamera& camera, const Vector6d& xi) {
  Scene s;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.9, 0.9), depth(0.8, 4.0);
  while (s.points.size() < 200) {
    const double z = depth(rng);
    const Eigen::Vector3d P(u(rng) * z * camera.cx / camera.fx, u(rng) * z * camera.cy / camera.fy, z);
    s.points.push_back(P);
    (void)s.frame.keypoints.push_back(observe(camera, seenOnItsRow(camera, xi, P), s.points.size() % 4 != 0));
  }
  s.frame.keypoint_grid.setBounds(0, 0, float(camera.width), float(camera.height));
  s.frame.keypoint_grid.build(int(s.frame.keypoints.size()),
                              [&s](int i) { return s.frame.keypoints[i].px_undist; });
  return s;
}

TEST(RollingShutter, KeypointsMoveToTheMiddleRowCamera) {
  const PinholeCamera camera = testCamera();
  const Vector6d xi = fastTwist();
  Scene s = makeScene(camera, xi);

  double worst_before = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const Eigen::Vector2d truth = camera.project(s.points[i]);
    worst_before = std::max(worst_before, (s.frame.keypoints[i].px_undist.cast<double>() - truth).norm());
  }
  // The distortion is real: rows far from the middle are off by many pixels.
  EXPECT_GT(worst_before, 8.0);

  compensateRollingShutter(camera, camera.rolling_shutter_readout_s, xi, &s.frame);
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const KeypointObservation& kp = s.frame.keypoints[i];
    const Eigen::Vector2d truth = camera.project(s.points[i]);
    if (kp.depth_m > 0) {
      // With depth the correction is exact up to the row's sub-pixel fixed point.
      EXPECT_LT((kp.px_undist.cast<double>() - truth).norm(), 0.02) << i;
      EXPECT_LT((kp.P_cam.cast<double>() - s.points[i]).norm(), 1e-4) << i;
      EXPECT_NEAR(kp.depth_m, s.points[i].z(), 1e-4);
      EXPECT_NEAR(kp.u_right, truth.x() - camera.fx * camera.baseline_m / s.points[i].z(), 0.02);
    } else {
      // Without depth the translation part uses a nominal depth: under a pixel (0.11 m/s for at
      // most 15 ms, seen at 0.8 m instead of 2 m: fx * 1.7 mm * (1/0.8 - 1/2) = 0.66 px).
      EXPECT_LT((kp.px_undist.cast<double>() - truth).norm(), 0.7) << i;
    }
  }
  // The matching grid follows the new positions.
  for (std::size_t i = 0; i < s.frame.keypoints.size(); ++i) {
    const Eigen::Vector2f p = s.frame.keypoints[i].px_undist;
    bool found = false;
    s.frame.keypoint_grid.forEachNear(p.x(), p.y(), 0.5f, [&](int k) { found = found || k == int(i); });
    EXPECT_TRUE(found) << i;
  }
}

TEST(RollingShutter, LinesAndSamplesMoveToTheMiddleRowCamera) {
  const PinholeCamera camera = testCamera();
  const Vector6d xi = fastTwist();
  // A 3D segment spanning many rows, sampled at 5 points.
  const Eigen::Vector3d A(-0.3, -0.6, 1.8), B(0.4, 0.7, 2.6);
  LineObservation line;
  const Eigen::Vector3d A_row = seenOnItsRow(camera, xi, A), B_row = seenOnItsRow(camera, xi, B);
  line.start_px = camera.project(A_row).cast<float>();
  line.end_px = camera.project(B_row).cast<float>();
  line.num_samples = 5;
  std::array<Eigen::Vector3d, 5> samples;
  for (int s = 0; s < 5; ++s) {
    samples[s] = A + (0.1 + 0.2 * s) * (B - A);
    const Eigen::Vector3d X = seenOnItsRow(camera, xi, samples[s]);
    line.sample_P_cam[s] = X.cast<float>();
    line.sample_px[s] = camera.project(X).cast<float>();
  }
  FrameFeatures frame;
  (void)frame.lines.push_back(line);

  auto distance_to_line = [&camera](const LineObservation& l, const Eigen::Vector3d& P) {
    const Eigen::Vector2d p = camera.project(P);
    const Eigen::Vector3d h = Eigen::Vector3d(l.start_px.x(), l.start_px.y(), 1)
                                  .cross(Eigen::Vector3d(l.end_px.x(), l.end_px.y(), 1));
    return std::abs(h.dot(Eigen::Vector3d(p.x(), p.y(), 1))) / std::hypot(h.x(), h.y());
  };
  double worst_before = 0;  // uncompensated: the true segment lies off the observed line
  for (const Eigen::Vector3d& P : samples) worst_before = std::max(worst_before, distance_to_line(line, P));
  EXPECT_GT(worst_before, 2.0);

  compensateRollingShutter(camera, camera.rolling_shutter_readout_s, xi, &frame);
  const LineObservation& out = frame.lines[0];
  for (const Eigen::Vector3d& P : samples) {
    EXPECT_LT(distance_to_line(out, P), 0.3);
    EXPECT_LT(std::abs(out.l.dot(Eigen::Vector3d(camera.project(P).x(), camera.project(P).y(), 1))), 0.3);
  }
  for (int s = 0; s < 5; ++s) {
    EXPECT_LT((out.sample_P_cam[s].cast<double>() - samples[s]).norm(), 1e-4) << s;
  }
}

TEST(RollingShutter, GlobalShutterLeavesTheFrameUnchanged) {
  const PinholeCamera camera = testCamera();
  Scene s = makeScene(camera, fastTwist());
  const FrameFeatures before = s.frame;
  compensateRollingShutter(camera, 0.0, fastTwist(), &s.frame);
  for (std::size_t i = 0; i < before.keypoints.size(); ++i) {
    EXPECT_EQ(s.frame.keypoints[i].px_undist, before.keypoints[i].px_undist);
    EXPECT_EQ(s.frame.keypoints[i].P_cam, before.keypoints[i].P_cam);
  }
}

}  // namespace
}  // namespace plumb

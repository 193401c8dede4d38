// Covariance files (both kinds, round trip, refusals) and NEES against ground truth
// (drivers/trajectory/evaluate_nees.h): errors drawn from the covariances that claim them give
// NEES/dof ~ 1 and ~95% inside the ellipsoid; a covariance 4x too small gives ~4; the tracked
// poses' gauge is the estimate's first pose, whatever world frame the estimate uses.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Cholesky>

#include "tests/drivers/dataset_test_support.h"
#include "drivers/trajectory/covariance_io.h"
#include "drivers/trajectory/evaluate_nees.h"
#include "solver/se3.h"

namespace plumb {
namespace {

using testing::TempDir;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

Matrix6d someCovariance(double sigma_t, double sigma_r) {
  Matrix6d C = Matrix6d::Zero();
  C.diagonal() << sigma_t * sigma_t, 2 * sigma_t * sigma_t, 0.5 * sigma_t * sigma_t, sigma_r * sigma_r,
      sigma_r * sigma_r, 3 * sigma_r * sigma_r;
  C(0, 4) = C(4, 0) = 0.5 * sigma_t * sigma_r;  // a translation-rotation coupling
  return C;
}

// A smooth ground-truth path sampled at 100 Hz.
std::vector<StampedPose> groundTruth(double seconds) {
  std::vector<StampedPose> gt;
  for (int i = 0; i <= int(seconds * 100); ++i) {
    const double t = 100.0 + i * 0.01;
    StampedPose p;
    p.timestamp = t;
    p.T_world_cam = Eigen::Translation3d(std::sin(t), 0.5 * std::cos(0.7 * t), 0.2 * t) *
                    Eigen::AngleAxisd(0.3 * std::sin(t), Eigen::Vector3d(0.2, 1, 0.1).normalized());
    gt.push_back(p);
  }
  return gt;
}

Vector6d draw(const Matrix6d& C, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vector6d z;
  for (int i = 0; i < 6; ++i) z(i) = n(rng);
  return Matrix6d(C.llt().matrixL()) * z;
}

TEST(CovarianceFiles, RoundTripBothKindsAndMarkers) {
  TempDir dir;
  StampedCovariance a, b, none;
  a.timestamp = 10.5;
  a.valid = true;
  a.covariance = someCovariance(0.01, 0.002);
  b = a;
  b.timestamp = 11.25;
  b.has_relative = true;
  b.previous_timestamp = 10.5;
  b.T_previous_this = Eigen::Translation3d(0.1, -0.2, 0.3) * Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY());
  b.relative_covariance = someCovariance(0.003, 0.001);
  none.timestamp = 12.0;
  CovarianceWriter writer;
  ASSERT_TRUE(writer.open(dir.file("kf.txt")).ok());
  for (const StampedCovariance& c : {a, b, none}) ASSERT_TRUE(writer.append(c).ok());
  ASSERT_TRUE(writer.close().ok());
  CovarianceFile file;
  ASSERT_TRUE(readCovarianceFile(dir.file("kf.txt"), &file).ok());
  ASSERT_EQ(file.kind, CovarianceFileKind::kKeyframe);
  ASSERT_EQ(file.keyframes.size(), 3u);
  EXPECT_FALSE(file.keyframes[0].has_relative);
  EXPECT_TRUE(file.keyframes[1].has_relative);
  EXPECT_FALSE(file.keyframes[2].valid);
  EXPECT_NEAR(file.keyframes[1].previous_timestamp, 10.5, 1e-9);
  EXPECT_LT((file.keyframes[1].relative_covariance - b.relative_covariance).norm(), 1e-8 * b.relative_covariance.norm());
  EXPECT_LT((file.keyframes[1].T_previous_this.matrix() - b.T_previous_this.matrix()).norm(), 1e-8);

  StampedTrackedCovariance f;
  f.timestamp = 20.0;
  f.valid = true;
  f.T_world_cam = b.T_previous_this;
  f.covariance = someCovariance(0.05, 0.01);
  f.covariance_local = someCovariance(0.002, 0.001);
  StampedTrackedCovariance g;
  g.timestamp = 20.1;
  StampedTrackedCovariance h = f;  // with the previous frame's pose in its map
  h.timestamp = 20.2;
  h.has_previous = true;
  h.previous_timestamp = 20.0;
  h.T_world_previous = Eigen::Translation3d(0.5, 0.25, -1) * Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitX());
  ASSERT_TRUE(writer.open(dir.file("tracked.txt"), CovarianceFileKind::kTracked).ok());
  ASSERT_TRUE(writer.append(f).ok());
  ASSERT_TRUE(writer.append(g).ok());
  ASSERT_TRUE(writer.append(h).ok());
  EXPECT_FALSE(writer.append(a).ok());  // a keyframe line into a tracked file
  ASSERT_TRUE(writer.close().ok());
  ASSERT_TRUE(readCovarianceFile(dir.file("tracked.txt"), &file).ok());
  ASSERT_EQ(file.kind, CovarianceFileKind::kTracked);
  ASSERT_EQ(file.frames.size(), 3u);
  EXPECT_TRUE(file.frames[0].valid);
  EXPECT_FALSE(file.frames[0].has_previous);
  EXPECT_FALSE(file.frames[1].valid);
  EXPECT_TRUE(file.frames[2].valid);
  EXPECT_TRUE(file.frames[2].has_previous);
  EXPECT_NEAR(file.frames[2].previous_timestamp, 20.0, 1e-9);
  EXPECT_LT((file.frames[2].T_world_previous.matrix() - h.T_world_previous.matrix()).norm(), 1e-8);
  EXPECT_LT((file.frames[0].covariance_local - f.covariance_local).norm(), 1e-8 * f.covariance_local.norm());
}

TEST(CovarianceFiles, BadLinesAreRefusedWithFileAndLine) {
  TempDir dir;
  CovarianceFile file;
  const std::string upper = " 1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1";
  EXPECT_TRUE(readCovarianceFile(dir.write("ok.txt", "5.0" + upper + "\n"), &file).ok());
  Status st = readCovarianceFile(dir.write("short.txt", "5.0 1 2 3\n"), &file);
  EXPECT_NE(st.message().find("short.txt:1"), std::string::npos) << st.message();
  st = readCovarianceFile(dir.write("neg.txt", "5.0 -1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1\n"), &file);
  EXPECT_NE(st.message().find("not positive semi-definite"), std::string::npos) << st.message();
  st = readCovarianceFile(dir.write("nan.txt", "5.0 nan" + upper.substr(2) + "\n"), &file);
  EXPECT_NE(st.message().find("not finite"), std::string::npos) << st.message();
  EXPECT_FALSE(readCovarianceFile(dir.write("empty.txt", "# nothing\n"), &file).ok());
}

TEST(Nees, InterpolatesGroundTruthAndRefusesGaps) {
  const std::vector<StampedPose> gt = groundTruth(1.0);
  Eigen::Isometry3d T;
  ASSERT_TRUE(interpolatePose(gt, 100.505, 0.05, &T));
  EXPECT_NEAR(T.translation().x(), 0.5 * (std::sin(100.5) + std::sin(100.51)), 1e-9);
  EXPECT_FALSE(interpolatePose(gt, 99.0, 0.05, &T));
  EXPECT_FALSE(interpolatePose(gt, 100.505, 0.001, &T));  // neighbours 10 ms apart: a gap
}

// Keyframe relative poses and tracked poses whose errors are drawn from their own covariances.
struct Drawn {
  CovarianceFile file;
  StampedPose anchor;
};

Drawn drawFromCovariances(const std::vector<StampedPose>& gt, const Eigen::Isometry3d& T_est_gt, double shrink,
                          unsigned seed) {
  std::mt19937 rng(seed);
  Drawn d;
  const Matrix6d C_rel = someCovariance(0.004, 0.002), C_local = someCovariance(0.002, 0.001);
  Eigen::Isometry3d G_previous = gt[0].T_world_cam;
  double t_previous = gt[0].timestamp;
  // The estimated world pose drifts: a random walk of the local errors (what its covariance chains).
  const Matrix6d C_step = 0.01 * C_local;
  Matrix6d C_walk = Matrix6d::Zero();
  Eigen::Isometry3d drift = Eigen::Isometry3d::Identity();  // left perturbation of T_cam_world
  for (std::size_t i = 3; i < gt.size(); i += 3) {
    const Eigen::Isometry3d& G = gt[i].T_world_cam;
    // Keyframe relative pose: T_prev_this (camera convention) perturbed on the right.
    StampedCovariance k;
    k.timestamp = gt[i].timestamp;
    k.valid = true;
    k.covariance = C_rel;
    k.has_relative = true;
    k.previous_timestamp = t_previous;
    k.T_previous_this = (G_previous.inverse() * G) * expSE3(draw(C_rel, rng));
    k.relative_covariance = C_rel * shrink;
    d.file.keyframes.push_back(k);
    G_previous = G;
    t_previous = gt[i].timestamp;
    // Tracked pose: T_cam_world(est) = exp(l) exp(w) T_cam_world(true) in the estimate's world,
    // l the frame's own error (covariance_local), w a slow random walk (the map's drift).
    drift = expSE3(draw(C_step, rng)) * drift;
    C_walk += C_step;  // small angles: the walk's covariance (adjoints ~ identity at this size)
    StampedTrackedCovariance f;
    f.timestamp = gt[i].timestamp;
    f.valid = true;
    const Eigen::Isometry3d T_cam_world_true = (T_est_gt * G).inverse();
    f.T_world_cam = (expSE3(draw(C_local, rng)) * drift * T_cam_world_true).inverse();
    f.covariance = (C_walk + C_local) * shrink;
    f.covariance_local = C_local * shrink;
    d.file.frames.push_back(f);
  }
  d.anchor.timestamp = gt[0].timestamp;
  d.anchor.T_world_cam = T_est_gt * gt[0].T_world_cam;
  return d;
}

TEST(Nees, ErrorsDrawnFromTheirCovariancesGiveOnePerDof) {
  const std::vector<StampedPose> gt = groundTruth(60.0);  // 2000 keyframes / frames
  // The estimate lives in another world frame: the gauge comes from its first pose.
  const Eigen::Isometry3d T_est_gt = Eigen::Translation3d(3, -1, 2) * Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitZ());
  const Drawn d = drawFromCovariances(gt, T_est_gt, 1.0, 1);
  NeesResult r;
  ASSERT_TRUE(evaluateNees(gt, d.file, d.anchor, NeesOptions{}, &r).ok());
  EXPECT_NEAR(r.keyframe_relative.mean_per_dof, 1.0, 0.08);
  EXPECT_NEAR(r.keyframe_relative.inside_95, 0.95, 0.02);
  EXPECT_NEAR(r.keyframe_relative.translation_mean_per_dof, 1.0, 0.1);
  EXPECT_NEAR(r.keyframe_relative.rotation_mean_per_dof, 1.0, 0.1);
  // The frame motion is the difference of two independent local errors (plus a walk step of 1%
  // of one): its covariance is their sum.
  EXPECT_NEAR(r.frame_motion.mean_per_dof, 1.0, 0.1);
  // A random walk's NEES is a time-correlated series: a looser bound.
  EXPECT_NEAR(r.tracked_world.mean_per_dof, 1.0, 0.35);
  EXPECT_GT(r.tracked_world.count, 1900u);

  const Drawn small = drawFromCovariances(gt, T_est_gt, 0.25, 1);  // covariances claim 4x too little
  ASSERT_TRUE(evaluateNees(gt, small.file, small.anchor, NeesOptions{}, &r).ok());
  EXPECT_NEAR(r.keyframe_relative.mean_per_dof, 4.0, 0.35);
  EXPECT_LT(r.keyframe_relative.inside_95, 0.6);
  EXPECT_NEAR(r.frame_motion.mean_per_dof, 4.0, 0.4);
}

// The map moves between two frames now and then (local BA after a keyframe, a loop): every later
// published pose jumps with it. The frame motion is graded from the previous frame as this
// frame's map places it (what MAVLink's velocity is made from), so it still gives ~1 per dof;
// without that pose in the file the difference of the published poses carries the jumps.
TEST(Nees, FrameMotionFromThePreviousPoseInTheFramesMap) {
  const std::vector<StampedPose> gt = groundTruth(60.0);
  const Drawn d = drawFromCovariances(gt, Eigen::Isometry3d::Identity(), 1.0, 2);
  CovarianceFile jumped = d.file;
  Eigen::Isometry3d map_move = Eigen::Isometry3d::Identity();
  for (std::size_t i = 1; i < jumped.frames.size(); ++i) {
    StampedTrackedCovariance& f = jumped.frames[i];
    if (i % 10 == 0) {  // 2 cm and 0.3 deg, far beyond the frames' millimetre sigmas
      map_move = Eigen::Translation3d(0.02, 0, -0.01) * Eigen::AngleAxisd(0.005, Eigen::Vector3d::UnitY()) * map_move;
    }
    f.has_previous = true;
    f.previous_timestamp = d.file.frames[i - 1].timestamp;
    f.T_world_previous = map_move * d.file.frames[i - 1].T_world_cam;
    f.T_world_cam = map_move * f.T_world_cam;
  }
  NeesResult with, without;
  ASSERT_TRUE(evaluateNees(gt, jumped, d.anchor, NeesOptions{}, &with).ok());
  EXPECT_NEAR(with.frame_motion.mean_per_dof, 1.0, 0.1);
  for (StampedTrackedCovariance& f : jumped.frames) f.has_previous = false;
  ASSERT_TRUE(evaluateNees(gt, jumped, d.anchor, NeesOptions{}, &without).ok());
  EXPECT_GT(without.frame_motion.mean_per_dof, 5.0);
  EXPECT_EQ(with.frame_motion.count, without.frame_motion.count);
}

}  // namespace
}  // namespace plumb

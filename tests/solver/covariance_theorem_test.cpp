// The paper's theorem (section V-C, eqs. 23-25): with landmark sets h and f observed by the same
// keyframes, the pose covariances of the three local BAs satisfy
//   C_g^-1 = C_h^-1 + C_f^-1,    C_h - C_g >= 0,    C_f - C_g >= 0,
// so adding landmarks never grows any eigenvalue of the pose covariance.
#include <random>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "solver/local_ba.h"
#include "tests/support/synthetic_window.h"

namespace plumb::testing {
namespace {

// Covariance of the free poses with only the landmarks in `keep` (others get no observations).
Eigen::MatrixXd poseCovariance(const SyntheticWindow& w, const std::vector<bool>& keep) {
  LocalBundleAdjuster ba;
  ba.reserve(static_cast<int>(w.T_cam_world_true.size()), static_cast<int>(w.P_world_true.size()),
             static_cast<int>(w.observations.size()));
  ba.setCamera(w.camera);
  for (size_t i = 0; i < w.T_cam_world_true.size(); ++i) ba.addKeyframe(w.T_cam_world_true[i], w.fixed[i]);
  for (const Eigen::Vector3d& P : w.P_world_true) ba.addLandmark(P);
  for (const SyntheticObservation& obs : w.observations) {
    if (!keep[obs.landmark]) continue;
    if (obs.kind == ObservationKind::kStereoPoint) {
      ba.addStereoPointObservation(obs.keyframe, obs.landmark, obs.z, obs.information);
    } else if (obs.kind == ObservationKind::kMonoPoint) {
      ba.addMonoPointObservation(obs.keyframe, obs.landmark, obs.z.head<2>(), obs.information.topLeftCorner<2, 2>());
    } else {
      ba.addLineObservation(obs.keyframe, obs.landmark, obs.z, obs.information(0, 0));
    }
  }
  LocalBaOptions options;
  options.kernel = RobustKernelType::kNone;  // plain Gaussian MLE covariance, as in the paper
  EXPECT_TRUE(ba.computeCovariance(options));
  return ba.fullCovariance();
}

Eigen::MatrixXd inverse(const Eigen::MatrixXd& C) {
  return C.llt().solve(Eigen::MatrixXd::Identity(C.rows(), C.cols()));
}

double minEigenvalue(const Eigen::MatrixXd& M) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(0.5 * (M + M.transpose())).eigenvalues()(0);
}

void checkTheorem(const SyntheticWindow& w, const std::vector<bool>& in_h) {
  std::vector<bool> in_f(in_h.size());
  for (size_t j = 0; j < in_h.size(); ++j) in_f[j] = !in_h[j];
  const std::vector<bool> all(in_h.size(), true);
  const Eigen::MatrixXd C_h = poseCovariance(w, in_h);
  const Eigen::MatrixXd C_f = poseCovariance(w, in_f);
  const Eigen::MatrixXd C_g = poseCovariance(w, all);
  ASSERT_GT(C_h.rows(), 0);
  ASSERT_EQ(C_f.rows(), C_h.rows());
  ASSERT_EQ(C_g.rows(), C_h.rows());
  const Eigen::MatrixXd info_g = inverse(C_g);
  const Eigen::MatrixXd info_sum = inverse(C_h) + inverse(C_f);
  EXPECT_LT((info_g - info_sum).norm() / info_g.norm(), 1e-9);
  // PSD up to round-off relative to the size of the covariances.
  const double tolerance = 1e-9 * C_h.norm();
  EXPECT_GE(minEigenvalue(C_h - C_g), -tolerance);
  EXPECT_GE(minEigenvalue(C_f - C_g), -tolerance);
  // And adding landmarks strictly helps here (not part of the theorem, a sanity check).
  EXPECT_LT(C_g.trace(), C_h.trace());
  EXPECT_LT(C_g.trace(), C_f.trace());
}

SyntheticWindowConfig exactWindow(unsigned seed) {
  SyntheticWindowConfig config;
  config.seed = seed;
  config.num_keyframes = 6;
  // Two fixed keyframes: line samples carry no depth, so with one fixed keyframe the scale of a
  // lines-only window would be unobservable (C_f infinite).
  config.num_fixed = 2;
  config.num_points = 80;
  config.num_lines = 25;
  config.samples_per_line = 5;
  config.views_per_landmark = 4;
  config.pixel_noise = 0.0;  // exact observations: the line-sample blocks are exactly rank 2
  config.depth_noise = false;
  return config;
}

// h = map points, f = line-guidance samples: the paper's split.
TEST(CovarianceTheorem, PointsVersusLineGuidanceSamples) {
  for (unsigned seed : {21u, 22u, 23u}) {
    const SyntheticWindow w = makeSyntheticWindow(exactWindow(seed));
    std::vector<bool> in_h(w.P_world_true.size());
    for (size_t j = 0; j < in_h.size(); ++j) in_h[j] = !w.is_line_sample[j];
    checkTheorem(w, in_h);
  }
}

// A random split of a mixed set.
TEST(CovarianceTheorem, RandomSplit) {
  for (unsigned seed : {31u, 32u}) {
    const SyntheticWindow w = makeSyntheticWindow(exactWindow(seed));
    std::mt19937 rng(seed);
    std::vector<bool> in_h(w.P_world_true.size());
    for (size_t j = 0; j < in_h.size(); ++j) in_h[j] = (rng() % 2) == 0;
    checkTheorem(w, in_h);
  }
}

}  // namespace
}  // namespace plumb::testing

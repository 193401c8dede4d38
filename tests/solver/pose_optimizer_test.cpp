#include "solver/pose_optimizer.h"

#include <memory>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "platform/allocation_counter.h"
#include "solver/noise_model.h"
#include "solver/se3.h"
#include "tests/solver/synthetic_window.h"

namespace plumb::testing {
namespace {

struct PoseProblem {
  CameraIntrinsics camera{525.0, 525.0, 319.5, 239.5, 42.0};
  Eigen::Isometry3d T_cam_world_true = Eigen::Isometry3d::Identity();
  std::vector<PosePointObservation> points;
  std::vector<bool> point_is_outlier;
  std::vector<PoseLineObservation> lines;
  std::vector<bool> line_is_outlier;
};

// One frame seeing num_points map points (20% without depth) and num_lines x 5 line samples.
PoseProblem makePoseProblem(unsigned seed, int num_points, int num_lines, double outlier_fraction) {
  PoseProblem p;
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const NoiseModelOptions noise;
  p.T_cam_world_true = lookAtCamFromWorld(Eigen::Vector3d(0.2, -0.1, 0.0), Eigen::Vector3d(0.1, 0.2, 3.5));
  const Eigen::Isometry3d T_world_cam = p.T_cam_world_true.inverse();
  auto randomVisiblePoint = [&] {
    const double depth = 1.0 + 4.0 * uniform(rng);
    const Eigen::Vector3d ray((600.0 * uniform(rng) + 20.0 - p.camera.cx) / p.camera.fx,
                              (440.0 * uniform(rng) + 20.0 - p.camera.cy) / p.camera.fy, 1.0);
    return Eigen::Vector3d(T_world_cam * (depth * ray));
  };
  for (int n = 0; n < num_points; ++n) {
    PosePointObservation obs;
    obs.P_world = randomVisiblePoint();
    const Eigen::Vector3d P_cam = p.T_cam_world_true * obs.P_world;
    Eigen::Vector2d uv = projectToPixel(p.camera, P_cam) + 0.5 * Eigen::Vector2d(gauss(rng), gauss(rng));
    const bool outlier = uniform(rng) < outlier_fraction;
    if (outlier) uv += Eigen::Vector2d(20.0 + 60.0 * uniform(rng), -20.0 - 60.0 * uniform(rng));
    obs.has_depth = uniform(rng) > 0.2;
    const double depth = P_cam.z() + depthSigma(noise, P_cam.z()) * gauss(rng);
    obs.z << uv, uv.x() - p.camera.bf / depth;
    if (obs.has_depth) {
      obs.information = stereoPointInformation(noise, p.camera, 0, depth);
    } else {
      obs.information.setZero();
      obs.information.topLeftCorner<2, 2>() = monoPointInformation(noise, 0);
    }
    p.points.push_back(obs);
    p.point_is_outlier.push_back(outlier);
  }
  for (int n = 0; n < num_lines; ++n) {
    const Eigen::Vector3d A = randomVisiblePoint();
    const Eigen::Vector3d B = randomVisiblePoint();
    const Eigen::Vector2d a = projectToPixel(p.camera, p.T_cam_world_true * A) + 0.5 * Eigen::Vector2d(gauss(rng), gauss(rng));
    const Eigen::Vector2d b = projectToPixel(p.camera, p.T_cam_world_true * B) + 0.5 * Eigen::Vector2d(gauss(rng), gauss(rng));
    Eigen::Vector3d line = Eigen::Vector3d::Zero();
    normalizeLine(Eigen::Vector3d(a.x(), a.y(), 1.0).cross(Eigen::Vector3d(b.x(), b.y(), 1.0)), &line);
    const bool outlier = uniform(rng) < outlier_fraction;
    if (outlier) line.z() += 25.0;
    for (int s = 0; s < 5; ++s) {
      PoseLineObservation obs;
      obs.P_world = A + (s + 0.5) / 5.0 * (B - A);
      obs.line = line;
      obs.information = lineSampleInformation(noise, 0);
      p.lines.push_back(obs);
      p.line_is_outlier.push_back(outlier);
    }
  }
  return p;
}

TEST(PoseOptimizer, RecoversAPerturbedPoseAndClassifiesOutliers) {
  for (bool lm : {false, true}) {
    const PoseProblem p = makePoseProblem(41, 300, 30, 0.15);
    Vector6d delta;
    delta << 0.06, -0.04, 0.08, 0.03, -0.02, 0.025;
    const Eigen::Isometry3d T_initial = applyLeftIncrement(delta, p.T_cam_world_true);
    PoseOptimizerOptions options;
    options.levenberg_marquardt = lm;
    std::unique_ptr<bool[]> point_inliers(new bool[p.points.size()]);
    std::unique_ptr<bool[]> line_inliers(new bool[p.lines.size()]);
    const PoseResult result =
        optimizePose(p.camera, T_initial, p.points.data(), static_cast<int>(p.points.size()), p.lines.data(),
                     static_cast<int>(p.lines.size()), options, point_inliers.get(), line_inliers.get());
    EXPECT_LT(rotationError(result.T_cam_world, p.T_cam_world_true), 1e-3) << "LM " << lm;
    EXPECT_LT(centreError(result.T_cam_world, p.T_cam_world_true), 5e-3) << "LM " << lm;
    EXPECT_LT(result.final_cost, result.initial_cost);

    int outliers = 0, caught = 0, inliers = 0, rejected = 0, counted_inliers = 0;
    for (size_t i = 0; i < p.points.size(); ++i) {
      counted_inliers += point_inliers[i] ? 1 : 0;
      if (p.point_is_outlier[i]) {
        ++outliers;
        caught += point_inliers[i] ? 0 : 1;
      } else {
        ++inliers;
        rejected += point_inliers[i] ? 0 : 1;
      }
    }
    EXPECT_EQ(counted_inliers, result.num_point_inliers);
    ASSERT_GT(outliers, 20);
    EXPECT_EQ(caught, outliers) << "LM " << lm;
    EXPECT_LE(rejected, 0.1 * inliers) << "LM " << lm;  // ~5% by the chi-square threshold itself

    int line_outliers = 0, line_caught = 0, line_inliers_count = 0, line_rejected = 0;
    for (size_t i = 0; i < p.lines.size(); ++i) {
      if (p.line_is_outlier[i]) {
        ++line_outliers;
        line_caught += line_inliers[i] ? 0 : 1;
      } else {
        ++line_inliers_count;
        line_rejected += line_inliers[i] ? 0 : 1;
      }
    }
    ASSERT_GT(line_outliers, 5);
    EXPECT_EQ(line_caught, line_outliers);
    EXPECT_LE(line_rejected, 0.1 * line_inliers_count);

    ASSERT_TRUE(result.covariance_valid);
    EXPECT_TRUE(result.covariance.isApprox(result.covariance.transpose(), 1e-12));
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Matrix6d>(result.covariance).eigenvalues()(0), 0.0);
  }
}

// More observations of the same quality cannot make the pose less certain.
TEST(PoseOptimizer, CovarianceShrinksWithMoreObservations) {
  const PoseProblem p = makePoseProblem(42, 400, 0, 0.0);
  PoseOptimizerOptions options;
  std::unique_ptr<bool[]> inliers(new bool[p.points.size()]);
  const PoseResult few = optimizePose(p.camera, p.T_cam_world_true, p.points.data(), 100, nullptr, 0, options,
                                      inliers.get(), nullptr);
  const PoseResult many = optimizePose(p.camera, p.T_cam_world_true, p.points.data(), 400, nullptr, 0, options,
                                       inliers.get(), nullptr);
  ASSERT_TRUE(few.covariance_valid && many.covariance_valid);
  EXPECT_LT(many.covariance.trace(), few.covariance.trace());
}

TEST(PoseOptimizer, TooFewObservationsGiveNoCovarianceAndNoNaN) {
  const PoseProblem p = makePoseProblem(43, 1, 0, 0.0);
  bool inlier = false;
  const PoseResult result =
      optimizePose(p.camera, p.T_cam_world_true, p.points.data(), 1, nullptr, 0, PoseOptimizerOptions(), &inlier, nullptr);
  EXPECT_FALSE(result.covariance_valid);
  EXPECT_TRUE(result.T_cam_world.matrix().allFinite());
}

TEST(PoseOptimizer, MakesZeroHeapAllocations) {
  const PoseProblem p = makePoseProblem(44, 200, 20, 0.1);
  std::unique_ptr<bool[]> point_inliers(new bool[p.points.size()]);
  std::unique_ptr<bool[]> line_inliers(new bool[p.lines.size()]);
  Vector6d delta;
  delta << 0.02, 0.01, -0.02, 0.01, 0.0, -0.01;
  const AllocationScope scope;
  const PoseResult result = optimizePose(p.camera, applyLeftIncrement(delta, p.T_cam_world_true), p.points.data(),
                                         200, p.lines.data(), static_cast<int>(p.lines.size()), PoseOptimizerOptions(),
                                         point_inliers.get(), line_inliers.get());
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_GT(result.num_point_inliers, 150);
}

}  // namespace
}  // namespace plumb::testing

#include "solver/noise_model.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Core>
#include <gtest/gtest.h>

namespace plumb {
namespace {

const CameraIntrinsics kCamera{525.0, 525.0, 319.5, 239.5, 42.0};

TEST(NoiseModel, PixelSigmaGrowsWithThePyramidLevel) {
  const NoiseModelOptions options;
  EXPECT_DOUBLE_EQ(pixelSigma(options, 0), 1.0);
  EXPECT_NEAR(pixelSigma(options, 3), 1.2 * 1.2 * 1.2, 1e-15);
}

// The default scale factor's powers are tabulated (issue 22); the table must give std::pow's bits,
// and any other scale factor, level beyond the table or negative level the formula's.
TEST(NoiseModel, PixelSigmaEqualsTheFormulaBitForBit) {
  for (const double scale : {1.2, 1.25, 2.0, 1.2000000000000002}) {
    for (const double level0 : {1.0, 0.7}) {
      NoiseModelOptions options;
      options.scale_factor = scale;
      options.pixel_sigma_level0 = level0;
      for (int level = -2; level < 40; ++level) {
        const double expected = level0 * std::pow(scale, std::max(level, 0));
        EXPECT_EQ(pixelSigma(options, level), expected) << "scale " << scale << " level " << level;
      }
    }
  }
}

TEST(NoiseModel, DepthSigmaIsQuadraticWithAFloor) {
  const NoiseModelOptions options;
  EXPECT_NEAR(depthSigma(options, 2.0), 0.0015 * 4.0, 1e-15);
  EXPECT_DOUBLE_EQ(depthSigma(options, 0.1), options.min_depth_sigma);
}

// The closed-form information is the inverse of J diag(sp^2, sp^2, sd^2) J^T (paper eq. 28).
TEST(NoiseModel, StereoInformationInvertsThePropagatedCovariance) {
  const NoiseModelOptions options;
  for (int level : {0, 2, 5}) {
    for (double depth : {0.6, 1.5, 3.0, 6.0}) {
      const double sp = pixelSigma(options, level);
      const double sd = depthSigma(options, depth);
      Eigen::Matrix3d J;
      J << 1, 0, 0, 0, 1, 0, 1, 0, kCamera.bf / (depth * depth);
      const Eigen::Matrix3d sigma = J * Eigen::Vector3d(sp * sp, sp * sp, sd * sd).asDiagonal() * J.transpose();
      const Eigen::Matrix3d information = stereoPointInformation(options, kCamera, level, depth);
      EXPECT_LT((information * sigma - Eigen::Matrix3d::Identity()).norm(), 1e-9) << level << " " << depth;
      EXPECT_TRUE(information.isApprox(information.transpose()));
    }
  }
  EXPECT_TRUE(stereoPointInformation(options, kCamera, 0, 0.0).isZero());
}

TEST(NoiseModel, MonoAndLineInformation) {
  const NoiseModelOptions options;
  EXPECT_TRUE(monoPointInformation(options, 1).isApprox(Eigen::Matrix2d::Identity() / (1.2 * 1.2)));
  EXPECT_NEAR(lineSampleInformation(options, 2), 1.0 / std::pow(1.2, 4), 1e-15);
}

// Back-projection covariance against a numerically differentiated back-projection (fy < 0 too).
TEST(NoiseModel, BackProjectedPointCovariance) {
  const NoiseModelOptions options;
  for (double fy : {525.0, -525.0}) {
    CameraIntrinsics camera = kCamera;
    camera.fy = fy;
    const double u = 400.0, v = 100.0, d = 2.2;
    const int level = 1;
    auto backProject = [&](double uu, double vv, double dd) {
      return Eigen::Vector3d((uu - camera.cx) * dd / camera.fx, (vv - camera.cy) * dd / camera.fy, dd);
    };
    Eigen::Matrix3d J;
    const double h = 1e-6;
    J.col(0) = (backProject(u + h, v, d) - backProject(u - h, v, d)) / (2 * h);
    J.col(1) = (backProject(u, v + h, d) - backProject(u, v - h, d)) / (2 * h);
    J.col(2) = (backProject(u, v, d + h) - backProject(u, v, d - h)) / (2 * h);
    const double sp = pixelSigma(options, level);
    const double sd = depthSigma(options, d);
    const Eigen::Matrix3d expected = J * Eigen::Vector3d(sp * sp, sp * sp, sd * sd).asDiagonal() * J.transpose();
    const Eigen::Matrix3d covariance = backProjectedPointCovariance(options, camera, u, v, d, level);
    EXPECT_LT((covariance - expected).norm() / expected.norm(), 1e-8) << fy;
  }
}

// A line sample's anchor: its disparity measured like a keypoint's with sigma_d scaled, its pixel
// only along the 2D line (nothing across it: the line residual measures that).
TEST(NoiseModel, LineSampleAnchorMeasuresDepthAndTheSlideNotTheLineOffset) {
  const NoiseModelOptions options;
  const double depth = 2.0, scale = 2.0;
  const Eigen::Vector2d along = Eigen::Vector2d(3.0, 4.0).normalized();
  const Eigen::Vector2d across(-along.y(), along.x());
  const Eigen::Matrix3d info = lineSampleAnchorInformation(options, kCamera, 1, depth, along, scale);
  // z = [u, v, u_r]: a pixel shift moves u and u_r together, a disparity change u_r alone.
  const auto chi2 = [&](const Eigen::Vector2d& dp, double d_disparity) {
    const Eigen::Vector3d dz(dp.x(), dp.y(), dp.x() - d_disparity);
    return dz.dot(info * dz);
  };
  EXPECT_NEAR(chi2(across, 0.0), 0.0, 1e-12);
  const double sigma_pixel = pixelSigma(options, 1);
  EXPECT_NEAR(chi2(along, 0.0), 1.0 / (sigma_pixel * sigma_pixel), 1e-9);
  const double sigma_disparity = scale * depthSigma(options, depth) * kCamera.bf / (depth * depth);
  EXPECT_NEAR(chi2(Eigen::Vector2d::Zero(), sigma_disparity), 1.0, 1e-9);
  // The keypoint's own disparity information, for comparison: scale^2 larger.
  const Eigen::Matrix3d keypoint = stereoPointInformation(options, kCamera, 1, depth);
  const Eigen::Vector3d dz_disparity(0.0, 0.0, -1.0);
  EXPECT_NEAR(dz_disparity.dot(keypoint * dz_disparity) / dz_disparity.dot(info * dz_disparity), scale * scale, 1e-9);
  // No depth (below the model's minimum) or no scale: nothing.
  EXPECT_TRUE(lineSampleAnchorInformation(options, kCamera, 1, 0.01, along, scale).isZero());
  EXPECT_TRUE(lineSampleAnchorInformation(options, kCamera, 1, depth, along, 0.0).isZero());
}

}  // namespace
}  // namespace plumb

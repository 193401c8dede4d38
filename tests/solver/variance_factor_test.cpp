// solver/variance_factor.h: chi-square CDFs, sigma0^2 from truncated inlier sums, and local BA's
// sigma0^2 on a synthetic window whose noise is a known fraction of the model's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "solver/noise_model.h"
#include "solver/variance_factor.h"
#include "tests/support/synthetic_window.h"

namespace plumb {
namespace {

TEST(VarianceFactor, ChiSquareCdfAtKnownQuantiles) {
  EXPECT_NEAR(chiSquareCdf(1, 3.841459), 0.95, 1e-6);
  EXPECT_NEAR(chiSquareCdf(2, 5.991465), 0.95, 1e-6);
  EXPECT_NEAR(chiSquareCdf(3, 7.814728), 0.95, 1e-6);
  EXPECT_NEAR(chiSquareCdf(4, 9.487729), 0.95, 1e-6);
  EXPECT_NEAR(chiSquareCdf(5, 11.070498), 0.95, 1e-6);
  EXPECT_EQ(chiSquareCdf(3, 0.0), 0.0);
}

// Inliers = draws of s * chi2_k below the thresholds; the estimate recovers s within 10% (at
// s = 2.5 a third of the draws are cut away, so the estimate is the noisier one).
TEST(VarianceFactor, RecoversTheScaleOfTruncatedChiSquareSums) {
  const OutlierChi2 thresholds;
  for (double s : {0.2, 1.0, 2.5}) {
    std::mt19937 rng(5);
    std::normal_distribution<double> n(0.0, 1.0);
    InlierChi2Sums sums;
    for (int i = 0; i < 6000; ++i) {
      const int dof = 1 + i % 3;
      double chi2 = 0;
      for (int k = 0; k < dof; ++k) chi2 += s * std::pow(n(rng), 2);
      const double threshold = dof == 1 ? thresholds.line : dof == 2 ? thresholds.mono : thresholds.stereo;
      if (chi2 <= threshold) sums.add(dof, chi2);
    }
    EXPECT_NEAR(varianceFactor(sums, 0.0, thresholds), s, 0.1 * s) << "s " << s;
    // Ignoring the truncation would be off by far more at s = 2.5 (the test can tell).
    if (s > 2) {
      EXPECT_LT((sums.chi2[0] + sums.chi2[1] + sums.chi2[2]) / sums.errorDof(), 0.8 * s);
    }
  }
  InlierChi2Sums few;
  few.add(3, 100.0);
  EXPECT_EQ(varianceFactor(few, 0.0, thresholds), 1.0);  // too little redundancy: the model as it is
}

// A window whose pixel noise is half the model's 1 px: sigma0^2 ~ 0.25 for the pixel-dominated
// errors (depth noise is drawn at the model's level, so the result lies between 0.25 and 1).
// The default synthetic window (depth noise drawn from the model) with this pixel noise, solved.
void solveWindow(double pixel_noise, const LocalBaOptions& options, LocalBundleAdjuster* ba) {
  testing::SyntheticWindowConfig config;
  config.pixel_noise = pixel_noise;
  testing::loadWindow(testing::makeSyntheticWindow(config), true, ba);
  ASSERT_TRUE(ba->solve(options).ok());
}

TEST(VarianceFactor, LocalBaSeesNoiseBelowTheModel) {
  const LocalBaOptions options;
  LocalBundleAdjuster ba;
  solveWindow(0.5, options, &ba);
  const double s = ba.varianceFactor(options);
  EXPECT_GT(s, 0.15);
  EXPECT_LT(s, 0.8);
  LocalBundleAdjuster ba1;
  solveWindow(1.0, options, &ba1);
  EXPECT_NEAR(ba1.varianceFactor(options), 1.0, 0.2);
}

// Variance components: pixel noise at half the model (component 0.25), depth noise at the model
// (1.0). Each part gets its own factor; the pooled factor lies in between and fits neither.
TEST(VarianceFactor, LocalBaSeparatesPixelAndDepthComponents) {
  const LocalBaOptions options;
  LocalBundleAdjuster ba;
  solveWindow(0.5, options, &ba);
  const PointVarianceComponents c = ba.varianceComponents(options);
  EXPECT_GT(c.redundancy, 100.0);
  EXPECT_NEAR(c.pixel, 0.25, 0.06);
  EXPECT_NEAR(c.depth, 1.0, 0.25);
  const double pooled = ba.varianceFactor(options);
  EXPECT_GT(pooled, c.pixel + 0.05);
  EXPECT_LT(pooled, c.depth - 0.1);
}

// The stereo information split into pixel and disparity parts: the parts' chi2 add up to the whole
// for the model's information, and scaling both parts by s is scaling the information by s.
TEST(VarianceFactor, StereoInformationSplitsIntoPixelAndDepth) {
  const CameraIntrinsics camera{525.0, 525.0, 319.5, 239.5, 525.0 * 0.08};
  const NoiseModelOptions noise;
  const Eigen::Matrix3d information = stereoPointInformation(noise, camera, 1, 2.5);
  const Eigen::Vector3d e(0.7, -0.4, 1.9);
  double pixel = 0, depth = 0;
  splitStereoChi2(information, e, &pixel, &depth);
  EXPECT_NEAR(pixel + depth, e.dot(information * e), 1e-9 * e.dot(information * e));
  EXPECT_NEAR(pixel, (0.49 + 0.16) / std::pow(pixelSigma(noise, 1), 2), 1e-9);
  EXPECT_TRUE(scaleStereoInformation(information, 3.0, 3.0).isApprox(3.0 * information, 1e-12));
  // Depth scaled alone: the pixel part of the chi2 is unchanged, the depth part scaled.
  const Eigen::Matrix3d depth_scaled = scaleStereoInformation(information, 1.0, 0.25);
  double pixel2 = 0, depth2 = 0;
  splitStereoChi2(depth_scaled, e, &pixel2, &depth2);
  EXPECT_NEAR(pixel2, pixel, 1e-9 * pixel);
  EXPECT_NEAR(depth2, 0.25 * depth, 1e-9 * depth);
}

// The matrix form scaleStereoInformation had before it was written out for the model's zeros
// (issue 22): every product of 0 or +-1 computed, so the signs of zero results are its own.
Eigen::Matrix3d referenceScaleStereoInformation(const Eigen::Matrix3d& information, double pixel_scale,
                                                double depth_scale) {
  Eigen::Matrix3d T = Eigen::Matrix3d::Identity();
  T(2, 0) = 1.0;
  T(2, 2) = -1.0;
  const Eigen::Vector3d d(std::sqrt(pixel_scale), std::sqrt(pixel_scale), std::sqrt(depth_scale));
  const Eigen::Matrix3d information_y = d.asDiagonal() * (T.transpose() * information * T) * d.asDiagonal();
  return T.transpose() * information_y * T;
}

// Bit for bit where the compiler evaluates both forms with the same roundings (x86-64 without FMA,
// the release build); elsewhere (aarch64: GCC contracts a * b + c into fused multiply-adds, in each
// form differently) within a relative 1e-12, as the other kernel oracles of tests/solver.
void expectSameBits3x3(const Eigen::Matrix3d& got, const Eigen::Matrix3d& expected, int trial) {
  for (int i = 0; i < 9; ++i) {
#if defined(__x86_64__) && !defined(__FMA__)
    ASSERT_EQ(std::memcmp(&got(i), &expected(i), sizeof(double)), 0)
        << trial << " entry " << i << ": " << got(i) << " vs " << expected(i);
#else
    if (!std::isfinite(expected(i))) {
      ASSERT_EQ(std::isnan(got(i)), std::isnan(expected(i))) << trial << " entry " << i;
      if (!std::isnan(expected(i))) {
        ASSERT_EQ(got(i), expected(i)) << trial << " entry " << i;
      }
      continue;
    }
    ASSERT_NEAR(got(i), expected(i), 1e-12 * std::max(1.0, std::abs(expected(i))))
        << trial << " entry " << i << ": " << got(i) << " vs " << expected(i);
#endif
  }
}

TEST(VarianceFactor, ScaledStereoInformationEqualsTheMatrixFormBitForBit) {
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const CameraIntrinsics camera{525.0, 525.0, 319.5, 239.5, 525.0 * 0.08};
  const NoiseModelOptions noise;
  auto scale = [&]() { return std::pow(10.0, 2.0 * unit(rng)); };
  for (int trial = 0; trial < 4000; ++trial) {
    Eigen::Matrix3d information;
    switch (trial % 4) {
      case 0:  // the model's (its disparity part cancels exactly in T^T I T)
        information = stereoPointInformation(noise, camera, trial % 8, 0.3 + 6.0 * std::abs(unit(rng)));
        break;
      case 1: {  // the model's zeros; other entries of any sign, with exact cancellations and zeros
        const double v[] = {unit(rng), unit(rng), unit(rng), unit(rng), unit(rng)};
        information << v[0], 0.0, v[1], 0.0, v[2], 0.0, v[3], 0.0, v[4];
        if (trial % 3 == 0) information(2, 0) = -information(0, 0);
        if (trial % 5 == 0) information(0, 2) = -information(2, 2);
        if (trial % 7 == 0) information(1, 1) = trial % 2 ? 0.0 : -0.0;
        if (trial % 11 == 0) information(0, 0) = -0.0;
        if (trial % 13 == 0) information(2, 2) = -0.0;
        break;
      }
      case 2:  // general (the matrix form itself)
        for (int i = 0; i < 9; ++i) information(i) = unit(rng);
        break;
      default:  // a -0 where the model has +0, or a non-finite entry: the matrix form too
        information = stereoPointInformation(noise, camera, 0, 1.0 + std::abs(unit(rng)));
        if (trial % 8 == 3) information(1, 2) = -0.0;
        if (trial % 8 == 7) information(0, 0) = std::numeric_limits<double>::infinity();
        break;
    }
    const double pixel = trial % 9 == 0 ? 1.0 : scale();
    const double depth = trial % 10 == 0 ? 1.0 : scale();
    expectSameBits3x3(scaleStereoInformation(information, pixel, depth),
                   referenceScaleStereoInformation(information, pixel, depth), trial);
  }
  // Scales that are zero, negative or not finite take the matrix form.
  const Eigen::Matrix3d information = stereoPointInformation(noise, camera, 1, 2.0);
  for (const double s : {0.0, -1.0, std::numeric_limits<double>::infinity()}) {
    const Eigen::Matrix3d got = scaleStereoInformation(information, s, 2.0);
    const Eigen::Matrix3d expected = referenceScaleStereoInformation(information, s, 2.0);
    for (int i = 0; i < 9; ++i) {
      EXPECT_TRUE(std::memcmp(&got(i), &expected(i), sizeof(double)) == 0 || (std::isnan(got(i)) && std::isnan(expected(i))))
          << s << " " << i;
    }
  }
}

}  // namespace
}  // namespace plumb

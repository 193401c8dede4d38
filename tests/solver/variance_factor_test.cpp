// solver/variance_factor.h: chi-square CDFs, sigma0^2 from truncated inlier sums, and local BA's
// sigma0^2 on a synthetic window whose noise is a known fraction of the model's.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

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
TEST(VarianceFactor, LocalBaSeesNoiseBelowTheModel) {
  testing::SyntheticWindowConfig config;
  config.pixel_noise = 0.5;
  const testing::SyntheticWindow w = testing::makeSyntheticWindow(config);
  LocalBundleAdjuster ba;
  testing::loadWindow(w, true, &ba);
  LocalBaOptions options;
  ASSERT_TRUE(ba.solve(options).ok());
  const double s = ba.varianceFactor(options);
  EXPECT_GT(s, 0.15);
  EXPECT_LT(s, 0.8);
  testing::SyntheticWindowConfig model_noise = config;
  model_noise.pixel_noise = 1.0;
  const testing::SyntheticWindow w1 = testing::makeSyntheticWindow(model_noise);
  LocalBundleAdjuster ba1;
  testing::loadWindow(w1, true, &ba1);
  ASSERT_TRUE(ba1.solve(options).ok());
  EXPECT_NEAR(ba1.varianceFactor(options), 1.0, 0.2);
}

}  // namespace
}  // namespace plumb

// The front end attaches the paper's noise model (V-D): info_uvr = inv(J diag(sp^2, sp^2, sd^2) J^T)
// with J = [[1,0,0],[0,1,0],[1,0,fx b/d^2]], sp = 1.2^octave px, sd = 0.0015 d^2 m.
#include <cmath>

#include <gtest/gtest.h>

#include "pipeline/frontend/feature_extractor.h"
#include "tests/pipeline/frontend_test_support.h"

namespace plumb {
namespace {

TEST(FrontendNoiseModel, KeypointInformationFollowsThePaper) {
  auto scene = test::makeScene("textured", 41);
  ASSERT_TRUE(scene);
  const PinholeCamera& camera = scene->camera();
  FeatureExtractor extractor(camera, ExtractorOptions());
  auto features = std::make_unique<FrameFeatures>();
  ASSERT_TRUE(extractor.extract(test::renderFrame(*scene, 0), *features));
  int checked = 0;
  for (const KeypointObservation& kp : features->keypoints) {
    if (kp.depth_m <= 0) continue;
    const double d = kp.depth_m, sp = std::pow(1.2, kp.octave), sd = std::max(0.001, 0.0015 * d * d);
    Eigen::Matrix3d J;
    J << 1, 0, 0, 0, 1, 0, 1, 0, camera.fx * camera.baseline_m / (d * d);
    const Eigen::Matrix3d cov = J * Eigen::Vector3d(sp * sp, sp * sp, sd * sd).asDiagonal() * J.transpose();
    const Eigen::Matrix3d expected = cov.inverse();
    const Eigen::Matrix3d actual = kp.info_uvr.cast<double>();
    ASSERT_LT((actual - expected).norm(), 1e-3 * expected.norm()) << "depth " << d << " octave " << int(kp.octave);
    ++checked;
  }
  EXPECT_GT(checked, 300);
}

}  // namespace
}  // namespace plumb

// Lines and line-guidance samples: 2D geometry, the robust 3D fit, and the quality of kept
// samples against the true 3D line on synthetic scenes (noise-free and Kinect-like noise).
//
// "True 3D line" of a detected segment: the depth renders of the synthetic scene are exact, so
// we back-project the segment densely (every pixel between 10% and 90% of its length, depth
// interpolated bilinearly, pixels at depth discontinuities skipped) from the NOISE-FREE render and
// fit a line to those points with a two-pass 2 cm trim. Segments whose dense points are not a 3D line (fewer
// than 80% within 2 cm: e.g. a segment bent across a corner) have no true line and are not
// scored. The extractor only ever sees 5 sparse samples, from the noise-free or the noisy render.
#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "pipeline/frontend/feature_extractor.h"
#include "pipeline/frontend/line_extractor.h"
#include "pipeline/frontend/line_fit3d.h"
#include "tests/pipeline/frontend_test_support.h"

namespace plumb {
namespace {

struct TrueLine {
  bool valid = false;
  Eigen::Vector3f point, direction;
};

void fitLeastSquares(const std::vector<Eigen::Vector3f>& pts, Eigen::Vector3f* point, Eigen::Vector3f* dir) {
  Eigen::Vector3f c = Eigen::Vector3f::Zero();
  for (const auto& p : pts) c += p;
  c /= static_cast<float>(pts.size());
  Eigen::Matrix3f s = Eigen::Matrix3f::Zero();
  for (const auto& p : pts) s += (p - c) * (p - c).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> eig(s);
  *point = c;
  *dir = eig.eigenvectors().col(2);
}

TrueLine trueLineOf(const PinholeCamera& camera, const cv::Mat& exact_depth, double factor, const LineObservation& line) {
  TrueLine result;
  std::vector<Eigen::Vector3f> pts;
  const int steps = static_cast<int>(line.length_px);
  for (int k = 0; k <= steps; ++k) {
    const float t = 0.1f + 0.8f * k / std::max(1, steps);
    const Eigen::Vector2f uv = line.start_px + t * (line.end_px - line.start_px);
    const Eigen::Vector2d raw = camera.distortPoint(uv.x(), uv.y());
    // Exact depth, bilinear between the 4 neighbours; points next to a depth discontinuity (> 2 cm
    // between neighbours) are left out of the reference rather than guessed.
    const int x = static_cast<int>(std::floor(raw.x())), y = static_cast<int>(std::floor(raw.y()));
    if (x < 0 || y < 0 || x + 1 >= exact_depth.cols || y + 1 >= exact_depth.rows) continue;
    auto z = [&](int u, int v) { return exact_depth.at<uint16_t>(v, u) / static_cast<float>(factor); };
    const float z00 = z(x, y), z10 = z(x + 1, y), z01 = z(x, y + 1), z11 = z(x + 1, y + 1);
    const float lo = std::min({z00, z10, z01, z11}), hi = std::max({z00, z10, z01, z11});
    if (lo <= 0 || hi - lo > 0.02f) continue;
    const float ax = static_cast<float>(raw.x()) - x, ay = static_cast<float>(raw.y()) - y;
    const float d = (1 - ay) * ((1 - ax) * z00 + ax * z10) + ay * ((1 - ax) * z01 + ax * z11);
    if (d > 0) pts.push_back(camera.unproject(uv.x(), uv.y(), d).cast<float>());
  }
  if (pts.size() < 10) return result;
  Eigen::Vector3f point, dir;
  fitLeastSquares(pts, &point, &dir);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<Eigen::Vector3f> kept;
    for (const auto& p : pts) if (distanceToLine(p, point, dir) < 0.02f) kept.push_back(p);
    if (kept.size() < 0.8 * pts.size() || kept.size() < 5) return result;
    fitLeastSquares(kept, &point, &dir);
  }
  result.valid = true;
  result.point = point;
  result.direction = dir;
  return result;
}

TEST(LineGeometry, NormalisedCoefficientsGiveSignedPixelDistance) {
  LineObservation line;
  setLineGeometry(Eigen::Vector2f(10, 20), Eigen::Vector2f(110, 70), line);
  EXPECT_NEAR(line.l.x() * line.l.x() + line.l.y() * line.l.y(), 1.0, 1e-12);
  EXPECT_NEAR(line.l.dot(Eigen::Vector3d(10, 20, 1)), 0.0, 1e-9);
  EXPECT_NEAR(line.l.dot(Eigen::Vector3d(110, 70, 1)), 0.0, 1e-9);
  // A point 5 px off the line along the unit normal.
  const Eigen::Vector2d n(line.l.x(), line.l.y());
  const Eigen::Vector2d p = Eigen::Vector2d(60, 45) + 5 * n;
  EXPECT_NEAR(line.l.dot(Eigen::Vector3d(p.x(), p.y(), 1)), 5.0, 1e-9);
  EXPECT_NEAR(line.length_px, std::hypot(100.0, 50.0), 1e-4);
}

TEST(LineFit3d, RejectsOutliersAndRecoversTheLine) {
  const Eigen::Vector3f a(0.2f, -0.1f, 2.0f), dir = Eigen::Vector3f(1, 0.5f, 0.3f).normalized();
  std::array<Eigen::Vector3f, 8> pts;
  std::array<float, 8> thresholds;
  thresholds.fill(0.01f);
  for (int i = 0; i < 8; ++i) pts[i] = a + 0.1f * i * dir + Eigen::Vector3f(0.001f * (i % 3), -0.001f * (i % 2), 0);
  pts[2] += Eigen::Vector3f(0, 0, 0.3f);   // background reading
  pts[5] += Eigen::Vector3f(0, 0, 0.05f);
  pts[7] -= Eigen::Vector3f(0.04f, 0, 0);
  const Line3dFit fit = fitLine3dRobust(pts.data(), thresholds.data(), 8, 3);
  ASSERT_TRUE(fit.ok);
  EXPECT_EQ(fit.num_inliers, 5);
  EXPECT_FALSE(fit.inlier[2]);
  EXPECT_FALSE(fit.inlier[5]);
  EXPECT_FALSE(fit.inlier[7]);
  EXPECT_GT(std::abs(fit.direction.dot(dir)), 0.999f);
  EXPECT_LT(distanceToLine(a, fit.point, fit.direction), 0.005f);
  // Too few consistent points -> no fit.
  const Line3dFit bad = fitLine3dRobust(pts.data(), thresholds.data(), 8, 6);
  EXPECT_FALSE(bad.ok);
}

struct SampleScore {
  int lines_scored = 0, lines_without_truth = 0, samples = 0, samples_close = 0, lines_3d = 0, lines_total = 0;
};

// Extracts `measured` and scores its kept samples against the true lines from `exact`.
void scoreSamples(const PinholeCamera& camera, const RgbdImage& measured, const RgbdImage& exact, float tolerance_m,
                  float sigma_multiplier, SampleScore* score) {
  FeatureExtractor extractor(camera, ExtractorOptions());
  auto features = std::make_unique<FrameFeatures>();
  ASSERT_TRUE(extractor.extract(measured, *features));
  const NoiseModelOptions noise;
  for (const LineObservation& line : features->lines) {
    ++score->lines_total;
    if (!line.has_3d) continue;
    ++score->lines_3d;
    EXPECT_GE(line.num_samples, 3);
    EXPECT_NEAR(line.line_dir_cam.norm(), 1.f, 1e-4f);
    const TrueLine truth = trueLineOf(camera, exact.depth_raw, exact.depth_factor, line);
    if (!truth.valid) {
      ++score->lines_without_truth;
      continue;
    }
    ++score->lines_scored;
    for (int s = 0; s < line.num_samples; ++s) {
      const Eigen::Vector3f& P = line.sample_P_cam[s];
      const float allowed = std::max(tolerance_m, sigma_multiplier * static_cast<float>(depthSigma(noise, P.z())));
      ++score->samples;
      score->samples_close += distanceToLine(P, truth.point, truth.direction) < allowed;
      // The covariance is a valid 3D covariance, largest along the viewing ray (depth noise).
      EXPECT_GT(line.sample_cov[s].determinant(), 0.f);
    }
  }
}

TEST(LineGuidance, NoiseFreeSamplesLieOnTheTrueLine) {
  SampleScore score;
  for (const char* preset : {"textured", "low_texture"}) {
    auto scene = test::makeScene(preset, 11);
    ASSERT_TRUE(scene);
    for (int i : {0, 45, 90}) {
      const RgbdImage frame = test::renderFrame(*scene, i);
      scoreSamples(scene->camera(), frame, frame, 0.01f, 0.f, &score);
    }
  }
  std::printf("noise-free: %d lines (%d with 3D), %d scored, %d without a true 3D line; %d/%d samples within 1 cm\n",
              score.lines_total, score.lines_3d, score.lines_scored, score.lines_without_truth, score.samples_close,
              score.samples);
  ASSERT_GT(score.lines_scored, 100);
  EXPECT_GT(score.lines_3d, 0.6 * score.lines_total);
  EXPECT_GE(score.samples_close, 0.9 * score.samples);
}

TEST(LineGuidance, RobustFitKeepsTrueLineSamplesUnderKinectNoise) {
  SampleScore score;
  auto exact_scene = test::makeScene("textured", 12);
  auto noisy_scene = test::makeScene("textured", 12, /*depth_noise=*/true, /*edge_holes=*/true);
  ASSERT_TRUE(exact_scene && noisy_scene);
  for (int i : {0, 40, 80, 120}) {
    const RgbdImage exact = test::renderFrame(*exact_scene, i);
    const RgbdImage noisy = test::renderFrame(*noisy_scene, i);
    // With depth noise sigma_d = 0.0014 d^2 a sample cannot be closer than its own noise:
    // "on the line" means within max(1 cm, 3 sigma_d).
    scoreSamples(exact_scene->camera(), noisy, exact, 0.01f, 3.f, &score);
  }
  std::printf("kinect noise: %d lines (%d with 3D), %d scored; %d/%d kept samples on the true line; "
              "%.2f samples kept per 3D line\n",
              score.lines_total, score.lines_3d, score.lines_scored, score.samples_close, score.samples,
              score.lines_scored ? double(score.samples) / score.lines_scored : 0.0);
  ASSERT_GT(score.lines_scored, 100);
  EXPECT_GE(score.samples_close, 0.9 * score.samples);
  EXPECT_GT(double(score.samples) / score.lines_scored, 3.5) << "the fit should keep most of the 5 samples";
}

TEST(LineGuidance, PointsOnlyAndSampleCountOptionsAreHonoured) {
  auto scene = test::makeScene("textured", 13);
  ASSERT_TRUE(scene);
  const RgbdImage frame = test::renderFrame(*scene, 10);
  auto features = std::make_unique<FrameFeatures>();
  ExtractorOptions options;
  options.line_samples = 0;
  FeatureExtractor no_samples(scene->camera(), options);
  ASSERT_TRUE(no_samples.extract(frame, *features));
  ASSERT_GT(features->lines.size(), 20u);
  for (const LineObservation& line : features->lines) EXPECT_EQ(line.num_samples, 0);
  options.line_samples = static_cast<int>(kMaxLineSamples);
  FeatureExtractor ten(scene->camera(), options);
  ASSERT_TRUE(ten.extract(frame, *features));
  int max_samples = 0;
  for (const LineObservation& line : features->lines) max_samples = std::max<int>(max_samples, line.num_samples);
  EXPECT_EQ(max_samples, static_cast<int>(kMaxLineSamples));
  options.max_lines = 0;
  FeatureExtractor points_only(scene->camera(), options);
  ASSERT_TRUE(points_only.extract(frame, *features));
  EXPECT_EQ(features->lines.size(), 0u);
  EXPECT_GT(features->keypoints.size(), 500u);
}

TEST(ExtractorOptionsValidation, DefaultsAreValidAndBadValuesAreNamed) {
  EXPECT_EQ(validate(ExtractorOptions()), "");
  ExtractorOptions o;
  o.line_samples = 11;
  EXPECT_NE(validate(o).find("line_samples"), std::string::npos);
  o = ExtractorOptions();
  o.line_level = 8;
  EXPECT_NE(validate(o).find("line_level"), std::string::npos);
  o = ExtractorOptions();
  o.num_features = 5000;
  EXPECT_NE(validate(o).find("num_features"), std::string::npos);
}

TEST(LineGuidance, RealFrameLinesAreRankedAndMostlyHave3d) {
  RgbdImage frame;
  if (!test::loadTumRpyFrame(20, &frame)) GTEST_SKIP() << "TUM fr1/rpy not found under " << test::tumRpyDir();
  FeatureExtractor extractor(test::tum1Camera(), ExtractorOptions());
  auto features = std::make_unique<FrameFeatures>();
  ASSERT_TRUE(extractor.extract(frame, *features));
  ASSERT_GT(features->lines.size(), 60u);
  EXPECT_LE(features->lines.size(), 150u);
  int with_3d = 0;
  for (size_t i = 0; i < features->lines.size(); ++i) {
    const LineObservation& line = features->lines[i];
    EXPECT_GE(line.length_px, ExtractorOptions().min_line_length_px * 0.9f);
    if (i > 0) {
      EXPECT_LE(line.response, features->lines[i - 1].response);
    }
    with_3d += line.has_3d;
  }
  EXPECT_GT(with_3d, static_cast<int>(features->lines.size() / 2));
}

}  // namespace
}  // namespace plumb

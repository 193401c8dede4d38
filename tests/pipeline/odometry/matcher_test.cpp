// Matching by projection: precision on synthetic frame pairs with known motion, and the basic
// rules (radius, octave, ratio, one keypoint per match) on hand-made features.
//
// Ground truth: a point match (previous keypoint with depth -> current keypoint) is correct when
// the previous 3D point, moved by the TRUE relative pose, projects within 2 px * 1.2^octave of
// the current keypoint. A line match is correct when the previous line's kept 3D samples, moved by
// the true pose, project within 3 px (mean) of the matched current line. The matcher itself is
// given a PERTURBED pose (0.5 deg, 1.5 cm off), like a constant-velocity prediction would be.
#include <cmath>

#include <gtest/gtest.h>

#include "pipeline/frontend/feature_extractor.h"
#include "pipeline/odometry/matcher.h"
#include "tests/pipeline/frontend_test_support.h"

namespace plumb {
namespace {

// Spread of the exact depth in a (2r+1)^2 window: large at occluding edges.
float depthRange(const RgbdImage& image, const Eigen::Vector2f& px, int r) {
  float lo = 1e9f, hi = 0;
  const int x = static_cast<int>(std::lround(px.x())), y = static_cast<int>(std::lround(px.y()));
  for (int v = std::max(0, y - r); v <= std::min(image.depth_raw.rows - 1, y + r); ++v)
    for (int u = std::max(0, x - r); u <= std::min(image.depth_raw.cols - 1, x + r); ++u) {
      const float d = image.depth_raw.at<uint16_t>(v, u) / static_cast<float>(image.depth_factor);
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
  return hi - lo;
}

struct Precision {
  int points = 0, points_correct = 0, lines = 0, lines_correct = 0;
};

void matchPair(const SyntheticScene& scene, int i, int j, Precision* p) {
  const PinholeCamera& camera = scene.camera();
  FeatureExtractor extractor(camera, ExtractorOptions());
  auto previous = std::make_unique<FrameFeatures>(), current = std::make_unique<FrameFeatures>();
  const RgbdImage previous_image = test::renderFrame(scene, i);
  ASSERT_TRUE(extractor.extract(previous_image, *previous));
  ASSERT_TRUE(extractor.extract(test::renderFrame(scene, j), *current));
  const Eigen::Isometry3d T_current_previous_true = scene.T_world_cam(j).inverse() * scene.T_world_cam(i);
  Eigen::Isometry3d perturbation = Eigen::Isometry3d::Identity();
  perturbation.linear() = Eigen::AngleAxisd(0.5 * M_PI / 180, Eigen::Vector3d(0.3, 1, 0.2).normalized()).toRotationMatrix();
  perturbation.translation() = Eigen::Vector3d(0.01, -0.008, 0.007);
  const Eigen::Isometry3d T_current_previous_predicted = perturbation * T_current_previous_true;

  auto matcher = std::make_unique<ProjectionMatcher>();
  auto point_matches = std::make_unique<PointMatches>();
  matcher->matchPointsFrameToFrame(camera, *previous, T_current_previous_predicted, *current, *point_matches);
  for (const PointMatch& m : *point_matches) {
    const KeypointObservation& a = previous->keypoints[m.candidate];
    const KeypointObservation& b = current->keypoints[m.keypoint];
    ASSERT_GT(a.depth_m, 0.f);
    const Eigen::Vector2d truth = camera.project(T_current_previous_true * a.P_cam.cast<double>());
    const double tolerance = 2.0 * std::pow(1.2, b.octave);
    ++p->points;
    p->points_correct += (truth - b.px_undist.cast<double>()).norm() < tolerance;
    if (getenv("PLUMB_DEBUG_MATCH") && (truth - b.px_undist.cast<double>()).norm() >= tolerance)
      std::printf("wrong: err %.1f oct %d->%d dist %d depth %.2f range %.3f\n", (truth - b.px_undist.cast<double>()).norm(), a.octave, b.octave, m.distance, a.depth_m, depthRange(previous_image, a.px, 2 + a.octave));
  }
  auto line_matches = std::make_unique<LineMatches>();
  matcher->matchLinesFrameToFrame(camera, *previous, T_current_previous_predicted, *current, *line_matches);
  for (const LineMatch& m : *line_matches) {
    const LineObservation& a = previous->lines[m.candidate];
    const LineObservation& b = current->lines[m.line];
    ASSERT_TRUE(a.has_3d);
    double sum = 0;
    for (int s = 0; s < a.num_samples; ++s) {
      const Eigen::Vector2d uv = camera.project(T_current_previous_true * a.sample_P_cam[s].cast<double>());
      sum += std::abs(b.l.dot(Eigen::Vector3d(uv.x(), uv.y(), 1)));
    }
    ++p->lines;
    p->lines_correct += a.num_samples > 0 && sum / a.num_samples < 3.0;
  }
}

TEST(ProjectionMatcher, FrameToFramePrecisionOnSyntheticPairs) {
  Precision p;
  for (const char* preset : {"textured", "fast_rotation"}) {
    auto scene = test::makeScene(preset, 21);
    ASSERT_TRUE(scene);
    for (int i : {0, 50, 100}) matchPair(*scene, i, i + 3, &p);
  }
  std::printf("points: %d/%d correct (%.1f%%), lines: %d/%d correct (%.1f%%)\n", p.points_correct, p.points,
              100.0 * p.points_correct / std::max(1, p.points), p.lines_correct, p.lines,
              100.0 * p.lines_correct / std::max(1, p.lines));
  ASSERT_GT(p.points, 6 * 200) << "too few point matches to judge precision";
  ASSERT_GT(p.lines, 6 * 20) << "too few line matches to judge precision";
  EXPECT_GE(p.points_correct, 0.95 * p.points);
  EXPECT_GE(p.lines_correct, 0.95 * p.lines);
}

// Hand-made frame: keypoints at known places with known descriptors.
std::unique_ptr<FrameFeatures> handMadeFrame() {
  auto frame = std::make_unique<FrameFeatures>();
  auto add = [&](float u, float v, int octave, uint64_t word0) {
    KeypointObservation* kp = frame->keypoints.emplace_back();
    kp->px = kp->px_undist = Eigen::Vector2f(u, v);
    kp->octave = static_cast<int8_t>(octave);
    kp->angle_deg = 10;
    Descriptor256* d = frame->keypoint_descriptors.emplace_back();
    d->words = {word0, 0, 0, 0};
  };
  add(100, 100, 0, 0x0);              // 0
  add(105, 100, 0, 0xFFFFFFFFull);    // 1: 32 bits from keypoint 0's descriptor
  add(300, 200, 0, 0x0);              // 2: same look as 0, far away
  add(300, 205, 3, 0xF);              // 3: other octave
  frame->keypoint_grid.setBounds(0, 0, 640, 480);
  frame->keypoint_grid.build(static_cast<int>(frame->keypoints.size()), [&](int i) { return frame->keypoints[i].px_undist; });
  return frame;
}

TEST(ProjectionMatcher, RespectsRadiusOctaveThresholdAndUniqueness) {
  auto frame = handMadeFrame();
  MatcherOptions options;
  options.points.check_orientation = false;
  ProjectionMatcher matcher(options);
  auto out = std::make_unique<PointMatches>();
  std::array<PointCandidate, 4> c;
  c[0].px_undist = Eigen::Vector2f(102, 101);  // nearest look-alike: keypoint 0 (distance 0)
  c[1].px_undist = Eigen::Vector2f(130, 100);  // 30 px from everything: nothing within 15 px
  c[2].px_undist = Eigen::Vector2f(300, 202);  // octave 0: keypoint 2 (keypoint 3 is octave 3)
  c[3].px_undist = Eigen::Vector2f(101, 99);   // competes with c[0] for keypoint 0, with a worse code
  c[3].descriptor.words = {0x3, 0, 0, 0};
  ASSERT_EQ(matcher.matchPoints(c.data(), 4, *frame, *out), 2);
  std::array<int, 4> matched_keypoint{-1, -1, -1, -1};
  for (const PointMatch& m : *out) matched_keypoint[m.candidate] = m.keypoint;
  EXPECT_EQ(matched_keypoint[0], 0);
  EXPECT_EQ(matched_keypoint[1], -1);
  EXPECT_EQ(matched_keypoint[2], 2);
  EXPECT_EQ(matched_keypoint[3], -1) << "keypoint 0 goes to the closer descriptor";
  // A predicted octave 3 widens the radius (15 * 1.2^3 = 26 px) and selects keypoint 3.
  c[1].px_undist = Eigen::Vector2f(320, 205);
  c[1].octave = 3;
  c[1].descriptor.words = {0xF, 0, 0, 0};
  ASSERT_EQ(matcher.matchPoints(c.data() + 1, 1, *frame, *out), 1);
  EXPECT_EQ((*out)[0].keypoint, 3);
  // Hamming threshold: codes 96 and 128 bits away are rejected.
  c[0].descriptor.words = {~0ull, ~0ull, 0, 0};
  EXPECT_EQ(matcher.matchPoints(c.data(), 1, *frame, *out), 0);
}

}  // namespace
}  // namespace plumb

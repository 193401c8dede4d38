// Evaluation: rigid alignment, the benchmark's association rule, ATE and RPE on synthetic
// trajectories with known answers, and the two published reference answers.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tests/drivers/dataset_test_support.h"
#include "drivers/trajectory/evaluate.h"
#include "drivers/trajectory/rigid_alignment.h"

namespace plumb {
namespace {

Eigen::Isometry3d makeTransform(double angle_rad, const Eigen::Vector3d& axis, const Eigen::Vector3d& t) {
  return Eigen::Translation3d(t) * Eigen::AngleAxisd(angle_rad, axis.normalized());
}

TEST(RigidAlignment, RecoversAKnownRigidTransformExactly) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> coordinate(-3, 3);
  std::vector<Eigen::Vector3d> source, target;
  const Eigen::Isometry3d T_target_source = makeTransform(2.4, {0.3, -1, 0.5}, {1.5, -2, 0.25});
  for (int i = 0; i < 50; ++i) {
    source.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng));
    target.push_back(T_target_source * source.back());
  }
  Eigen::Isometry3d estimated;
  ASSERT_TRUE(alignRigid(source, target, &estimated).ok());
  EXPECT_LT((estimated.matrix() - T_target_source.matrix()).norm(), 1e-12);
  EXPECT_NEAR(estimated.linear().determinant(), 1.0, 1e-12);
}

TEST(RigidAlignment, MirroredDataStillGivesARotation) {
  std::vector<Eigen::Vector3d> source = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  std::vector<Eigen::Vector3d> target;
  for (const auto& p : source) target.emplace_back(p.x(), p.y(), -p.z());  // a reflection
  Eigen::Isometry3d estimated;
  ASSERT_TRUE(alignRigid(source, target, &estimated).ok());
  EXPECT_NEAR(estimated.linear().determinant(), 1.0, 1e-12);
}

TEST(RigidAlignment, RejectsTooFewOrDegeneratePoints) {
  Eigen::Isometry3d T;
  EXPECT_FALSE(alignRigid({{0, 0, 0}, {1, 0, 0}}, {{0, 0, 0}, {1, 0, 0}}, &T).ok());
  EXPECT_FALSE(alignRigid({{1, 1, 1}, {1, 1, 1}, {1, 1, 1}}, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, &T).ok());
  EXPECT_FALSE(alignRigid({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 0, 0}}, &T).ok());
}

TEST(TimestampAssociation, GreedyUniqueBySmallestDifference) {
  // 1.000 is closest to 1.004, but 1.004 is closer still to 1.005: greedy takes (1.005, 1.004)
  // first, then 1.000 gets the next free candidate 1.015 (|dt| 0.015 < 0.02).
  const std::vector<double> first = {1.000, 1.005, 2.0};
  const std::vector<double> second = {1.004, 1.015, 2.025};
  const std::vector<IndexPair> pairs = associateTimestamps(first, second);
  ASSERT_EQ(pairs.size(), 2u);  // 2.0 vs 2.025 is outside the window
  EXPECT_EQ(pairs[0].first, 0u);
  EXPECT_EQ(pairs[0].second, 1u);
  EXPECT_EQ(pairs[1].first, 1u);
  EXPECT_EQ(pairs[1].second, 0u);
  AssociationOptions wide;
  wide.max_dt_s = 0.03;
  EXPECT_EQ(associateTimestamps(first, second, wide).size(), 3u);
  EXPECT_TRUE(associateTimestamps({}, second).empty());
}

// A ground truth that moves and turns smoothly, sampled at `rate_hz` for `duration_s`.
std::vector<StampedPose> smoothTrajectory(double rate_hz, double duration_s, double t0 = 100.0) {
  std::vector<StampedPose> poses;
  for (int i = 0; i <= static_cast<int>(duration_s * rate_hz); ++i) {
    const double t = i / rate_hz;
    StampedPose p;
    p.timestamp = t0 + t;
    p.T_world_cam = makeTransform(0.3 * std::sin(0.5 * t), {0.2, 1, 0.1},
                                  {std::cos(0.4 * t), std::sin(0.4 * t), 0.1 * t});
    poses.push_back(p);
  }
  return poses;
}

TEST(Ate, RigidlyMovedCopyHasZeroErrorAndLostFramesAreIgnored) {
  const std::vector<StampedPose> gt = smoothTrajectory(100, 10);
  std::vector<StampedPose> estimate;
  const Eigen::Isometry3d T_est_gt = makeTransform(1.0, {1, 1, 0}, {3, -1, 2});
  for (std::size_t i = 0; i < gt.size(); i += 3) {
    StampedPose p = gt[i];
    p.timestamp += 0.005;  // within the association window
    p.T_world_cam = T_est_gt * p.T_world_cam;
    estimate.push_back(p);
  }
  estimate[5].valid = false;
  estimate[5].T_world_cam.translation() += Eigen::Vector3d(100, 0, 0);  // must not matter
  AteResult ate;
  ASSERT_TRUE(evaluateAte(gt, estimate, {}, &ate).ok());
  EXPECT_EQ(ate.pairs, estimate.size() - 1);
  EXPECT_LT(ate.translation_m.rmse, 1e-9);
  EXPECT_TRUE(ate.T_gt_est.isApprox(T_est_gt.inverse(), 1e-9));
}

TEST(Ate, KnownOffsetNoiseGivesKnownRmse) {
  // Alternating +-d offsets along one axis cannot be aligned away: RMSE = d exactly.
  const std::vector<StampedPose> gt = smoothTrajectory(30, 10);
  std::vector<StampedPose> estimate = gt;
  const double d = 0.02;
  for (std::size_t i = 0; i < estimate.size(); ++i)
    estimate[i].T_world_cam.translation().z() += (i % 2 ? d : -d);
  AteResult ate;
  ASSERT_TRUE(evaluateAte(gt, estimate, {}, &ate).ok());
  EXPECT_NEAR(ate.translation_m.rmse, d, 2e-4);
  EXPECT_NEAR(ate.translation_m.max, d, 1e-3);
}

TEST(Ate, DisjointTimestampsAreAnError) {
  const std::vector<StampedPose> gt = smoothTrajectory(30, 5, 100);
  const std::vector<StampedPose> estimate = smoothTrajectory(30, 5, 200);
  AteResult ate;
  const Status st = evaluateAte(gt, estimate, {}, &ate);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("only 0"), std::string::npos) << st.message();
}

TEST(Rpe, ConstantTranslationDriftGivesItsRate) {
  // Ground truth at rest; the estimate drifts 0.05 m/s along x. Stamps every 0.1 s, so the frame
  // closest to t + 1 s is exactly 1 s later and every RPE error is 0.05 m.
  const double drift_m_per_s = 0.05;
  std::vector<StampedPose> gt, estimate;
  const int frames = 60;
  for (int i = 0; i < frames; ++i) {
    StampedPose p;
    p.timestamp = 50.0 + 0.1 * i;
    p.T_world_cam = makeTransform(0.7, {1, 0, 1}, {1, 2, 3});
    gt.push_back(p);
    p.T_world_cam.translation().x() += drift_m_per_s * 0.1 * i;
    estimate.push_back(p);
  }
  RpeResult rpe;
  ASSERT_TRUE(evaluateRpe(gt, estimate, {}, &rpe).ok());
  // Frames whose 1 s partner would be the last frame or beyond are skipped (benchmark rule).
  EXPECT_EQ(rpe.pairs, static_cast<std::size_t>(frames - 11));
  EXPECT_NEAR(rpe.translation_m_per_s.rmse, drift_m_per_s, 1e-9);
  EXPECT_NEAR(rpe.translation_m_per_s.max, drift_m_per_s, 1e-9);
  EXPECT_NEAR(rpe.rotation_deg_per_s.rmse, 0.0, 1e-6);
}

TEST(Rpe, ConstantYawDriftGivesItsRate) {
  const double drift_deg_per_s = 3.0;
  std::vector<StampedPose> gt = smoothTrajectory(10, 8), estimate = gt;
  for (StampedPose& p : estimate) {
    const double t = p.timestamp - estimate.front().timestamp;
    // The estimate's world frame spins about world z at the drift rate: every relative motion
    // over 1 s is then off by exactly that rotation (conjugated into the camera frame).
    p.T_world_cam =
        Eigen::AngleAxisd(drift_deg_per_s * t * M_PI / 180, Eigen::Vector3d::UnitZ()) * p.T_world_cam;
  }
  RpeResult rpe;
  ASSERT_TRUE(evaluateRpe(gt, estimate, {}, &rpe).ok());
  EXPECT_NEAR(rpe.rotation_deg_per_s.rmse, drift_deg_per_s, 1e-6);
  EXPECT_NEAR(rpe.rotation_deg_per_s.min, drift_deg_per_s, 1e-6);
}

TEST(Rpe, TooShortEstimateIsAnError) {
  const std::vector<StampedPose> gt = smoothTrajectory(30, 5);
  std::vector<StampedPose> estimate(gt.begin(), gt.begin() + 10);  // 0.3 s
  RpeResult rpe;
  EXPECT_FALSE(evaluateRpe(gt, estimate, {}, &rpe).ok());
}

TEST(ErrorStatistics, MatchesHandComputedValues) {
  const ErrorStatistics s = computeErrorStatistics({3, 1, 4, 2});
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(30.0 / 4));
  EXPECT_DOUBLE_EQ(s.min, 1);
  EXPECT_DOUBLE_EQ(s.max, 4);
}

// The published answers of the benchmark's convention (datasets README).
void expectReferenceAte(const std::string& gt_file, const std::string& est_file, std::size_t pairs,
                        double rmse_m) {
  PLUMB_SKIP_WITHOUT_DATASET(dir, "reference_trajectories");
  std::vector<StampedPose> gt, estimate;
  Status st = readTumTrajectory(dir + "/" + gt_file, &gt);
  ASSERT_TRUE(st.ok()) << st.message();
  st = readTumTrajectory(dir + "/" + est_file, &estimate);
  ASSERT_TRUE(st.ok()) << st.message();
  AteResult ate;
  st = evaluateAte(gt, estimate, {}, &ate);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_EQ(ate.pairs, pairs);
  EXPECT_NEAR(ate.translation_m.rmse, rmse_m, 0.0001);
  RpeResult rpe;
  ASSERT_TRUE(evaluateRpe(gt, estimate, {}, &rpe).ok());
  EXPECT_GT(rpe.pairs, pairs / 2);
}

TEST(AteReference, Freiburg1XyzRgbdslam) {
  expectReferenceAte("freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-rgbdslam.txt", 786, 0.0135);
}

TEST(AteReference, Freiburg2DeskOrb) {
  expectReferenceAte("fr2_desk_groundtruth.txt", "fr2_desk_ORB.txt", 2223, 0.0081);
}

}  // namespace
}  // namespace plumb

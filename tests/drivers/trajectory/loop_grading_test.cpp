// The loop grader behind `plumb eval --loops` (drivers/trajectory/loop_grading.h) on a hand-made
// audit: a constraint perturbed by a known error is graded with that error (m, deg, sigmas of its
// own covariance), with the true baseline between the two views, and judged against the 5 cm /
// 2 deg / 3 sigma bounds; a rejected candidate is not graded; a loop outside the ground truth's
// time span has no ground truth.
#include <gtest/gtest.h>

#include <cmath>

#include "drivers/trajectory/loop_grading.h"

namespace plumb {
namespace {

// A straight 2 m walk along x over 4 s with a slow yaw, ground truth at 100 Hz.
std::vector<StampedPose> walkGroundTruth() {
  std::vector<StampedPose> gt;
  for (int i = 0; i <= 400; ++i) {
    StampedPose p;
    p.timestamp = 50.0 + i * 0.01;
    p.T_world_cam = Eigen::Translation3d(0.005 * i, 0.0, 0.0) * Eigen::AngleAxisd(0.001 * i, Eigen::Vector3d::UnitY());
    gt.push_back(p);
  }
  return gt;
}

// The true T_candidate_query of two ground-truth samples.
Eigen::Isometry3d trueRelative(const std::vector<StampedPose>& gt, int candidate, int query) {
  return gt[std::size_t(candidate)].T_world_cam.inverse() * gt[std::size_t(query)].T_world_cam;
}

AuditedLoop acceptedLoop(double candidate_t, double query_t, const Eigen::Isometry3d& T_candidate_query,
                         double sigma_m) {
  AuditedLoop a;
  a.query_id = 40;
  a.candidate_id = 2;
  a.query_t = query_t;
  a.candidate_t = candidate_t;
  a.outcome = "accepted";
  a.has_constraint = true;
  a.T_candidate_query = T_candidate_query;
  a.covariance = Matrix6d::Identity() * 1e-6;  // 1 mrad
  a.covariance.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * sigma_m * sigma_m;
  return a;
}

TEST(LoopGrading, GradesTheConstraintsErrorInMetresDegreesAndSigmasWithTheTrueBaseline) {
  const std::vector<StampedPose> gt = walkGroundTruth();
  const Eigen::Isometry3d truth = trueRelative(gt, 20, 320);  // 1.5 m, 0.3 rad apart
  // The constraint is off by 3 cm along the query camera's z: T_query_candidate = exp(e) G^-1, so
  // T_candidate_query = G exp(-e), a pure translation of -3 cm in the query frame.
  const Eigen::Isometry3d measured = truth * Eigen::Translation3d(0, 0, -0.03);
  LoopAuditFile audit;
  audit.candidates.push_back(acceptedLoop(gt[20].timestamp, gt[320].timestamp, measured, 0.01));  // 3 sigma
  audit.candidates.push_back(acceptedLoop(gt[20].timestamp, gt[320].timestamp, measured, 0.02));  // 1.5 sigma
  AuditedLoop rejected = acceptedLoop(gt[20].timestamp, gt[320].timestamp, measured, 0.02);
  rejected.outcome = "few_inliers";
  audit.candidates.push_back(rejected);
  audit.candidates.push_back(acceptedLoop(gt[20].timestamp, 99.0, measured, 0.02));  // no ground truth

  const LoopGrading g = gradeLoops(gt, audit, LoopGradingOptions());
  EXPECT_EQ(g.verified, 4u);
  EXPECT_EQ(g.accepted, 3u);
  EXPECT_EQ(g.graded, 2u);
  ASSERT_EQ(g.loops.size(), 3u);
  for (int k = 0; k < 2; ++k) {
    const GradedLoop& l = g.loops[std::size_t(k)];
    ASSERT_TRUE(l.has_ground_truth);
    EXPECT_NEAR(l.error_m, 0.03, 1e-9);
    EXPECT_NEAR(l.error_deg, 0.0, 1e-6);
    EXPECT_NEAR(l.baseline_m, truth.translation().norm(), 1e-9);
    EXPECT_NEAR(l.baseline_m, 1.5, 1e-9);
    EXPECT_NEAR(l.baseline_deg, 0.3 * 180.0 / M_PI, 1e-6);
  }
  // 3 cm against sigma 1 cm: 3 sigma, chi2 9 <= 20.06 and within 5 cm: correct; against 2 cm, 1.5.
  EXPECT_NEAR(g.loops[0].error_sigmas, 3.0, 1e-6);
  EXPECT_NEAR(g.loops[1].error_sigmas, 1.5, 1e-6);
  EXPECT_TRUE(g.loops[0].correct);
  EXPECT_FALSE(g.loops[2].has_ground_truth);
  EXPECT_EQ(g.correct, 2u);
}

TEST(LoopGrading, AConstraintBeyondItsCovarianceOrFiveCentimetresIsWrong) {
  const std::vector<StampedPose> gt = walkGroundTruth();
  const Eigen::Isometry3d truth = trueRelative(gt, 10, 300);
  LoopAuditFile audit;
  // 3 cm off claiming 5 mm: 6 sigma (chi2 36 > 20.06), though within 5 cm.
  audit.candidates.push_back(acceptedLoop(gt[10].timestamp, gt[300].timestamp,
                                          truth * Eigen::Translation3d(0.03, 0, 0), 0.005));
  // 6 cm off claiming 5 cm: 1.2 sigma, but beyond 5 cm.
  audit.candidates.push_back(acceptedLoop(gt[10].timestamp, gt[300].timestamp,
                                          truth * Eigen::Translation3d(0, 0.06, 0), 0.05));
  const LoopGrading g = gradeLoops(gt, audit, LoopGradingOptions());
  ASSERT_EQ(g.loops.size(), 2u);
  EXPECT_NEAR(g.loops[0].error_sigmas, 6.0, 1e-6);
  EXPECT_FALSE(g.loops[0].correct);
  EXPECT_NEAR(g.loops[1].error_m, 0.06, 1e-9);
  EXPECT_FALSE(g.loops[1].correct);
  EXPECT_EQ(g.correct, 0u);
  EXPECT_EQ(g.within_distance, 1u);
  EXPECT_DOUBLE_EQ(g.precision(), 0.0);
}

}  // namespace
}  // namespace plumb

// solver/rigid_fit.h: the least-squares rigid fit recovers a known motion, never returns a
// reflection, refuses too few pairs; RANSAC finds the motion through gross outliers and flags them.
#include "solver/rigid_fit.h"

#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace plumb {
namespace {

Eigen::Isometry3d knownMotion() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.3, -0.1, 0.7);
  return T;
}

std::vector<Eigen::Vector3d> scatteredPoints(int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> xy(-1.0, 1.0), z(1.0, 4.0);
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < n; ++i) p.emplace_back(xy(rng), xy(rng), z(rng));
  return p;
}

TEST(RigidFit, RecoversAKnownMotionExactly) {
  const Eigen::Isometry3d T_to_from = knownMotion();
  const std::vector<Eigen::Vector3d> from = scatteredPoints(20, 3);
  std::vector<Eigen::Vector3d> to;
  for (const auto& p : from) to.push_back(T_to_from * p);
  Eigen::Isometry3d T;
  ASSERT_TRUE(rigidFitKabsch(from.data(), to.data(), nullptr, int(from.size()), &T));
  EXPECT_LT((T.matrix() - T_to_from.matrix()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(RigidFit, GivesARotationForMirroredDataAndRefusesTooFewPairs) {
  const std::vector<Eigen::Vector3d> from = scatteredPoints(10, 5);
  std::vector<Eigen::Vector3d> mirrored;
  for (const auto& p : from) mirrored.emplace_back(-p.x(), p.y(), p.z());
  Eigen::Isometry3d T;
  ASSERT_TRUE(rigidFitKabsch(from.data(), mirrored.data(), nullptr, int(from.size()), &T));
  EXPECT_NEAR(T.linear().determinant(), 1.0, 1e-12);
  bool flags[10] = {true, true};  // two pairs flagged: not enough
  EXPECT_FALSE(rigidFitKabsch(from.data(), mirrored.data(), flags, 10, &T));
}

TEST(RigidRansac, FindsTheMotionThroughOutliersAndFlagsThem) {
  const Eigen::Isometry3d T_to_from = knownMotion();
  const int n = 60;
  const std::vector<Eigen::Vector3d> from = scatteredPoints(n, 7);
  std::vector<Eigen::Vector3d> to;
  for (int i = 0; i < n; ++i) {
    // Every third pair is a gross mismatch (metres off).
    to.push_back(i % 3 == 0 ? Eigen::Vector3d(from[i].y() * 3, 2.0 - from[i].x(), from[i].z() + 1.5)
                            : T_to_from * from[i]);
  }
  std::unique_ptr<bool[]> scratch(new bool[n]), inliers(new bool[n]);
  Eigen::Isometry3d T;
  const int count = rigidRansac(from.data(), to.data(), n, RigidRansacOptions{}, scratch.get(),
                                inliers.get(), &T);
  EXPECT_EQ(count, 40);
  for (int i = 0; i < n; ++i) EXPECT_EQ(bool(inliers[i]), i % 3 != 0) << i;
  EXPECT_LT((T.matrix() - T_to_from.matrix()).cwiseAbs().maxCoeff(), 1e-9);
  // The same call gives the same answer (seeded sampler).
  Eigen::Isometry3d again;
  EXPECT_EQ(rigidRansac(from.data(), to.data(), n, RigidRansacOptions{}, scratch.get(),
                        inliers.get(), &again),
            count);
  EXPECT_TRUE(again.matrix() == T.matrix());
}

}  // namespace
}  // namespace plumb

#include "solver/rigid_fit.h"

#include <algorithm>
#include <random>

#include <Eigen/SVD>

namespace plumb {

bool rigidFitKabsch(const Eigen::Vector3d* from, const Eigen::Vector3d* to, const bool* flags, int n,
                    Eigen::Isometry3d* T_to_from) {
  Eigen::Vector3d mean_from = Eigen::Vector3d::Zero(), mean_to = Eigen::Vector3d::Zero();
  int count = 0;
  for (int i = 0; i < n; ++i) {
    if (flags != nullptr && !flags[i]) continue;
    mean_from += from[i];
    mean_to += to[i];
    ++count;
  }
  if (count < 3) return false;
  mean_from /= count;
  mean_to /= count;
  Eigen::Matrix3d cross = Eigen::Matrix3d::Zero();
  for (int i = 0; i < n; ++i) {
    if (flags != nullptr && !flags[i]) continue;
    cross += (to[i] - mean_to) * (from[i] - mean_from).transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cross, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) D(2, 2) = -1;  // no reflection
  const Eigen::Matrix3d R = svd.matrixU() * D * svd.matrixV().transpose();
  T_to_from->setIdentity();
  T_to_from->linear() = R;
  T_to_from->translation() = mean_to - R * mean_from;
  return true;
}

namespace {

int countInliers(const Eigen::Vector3d* from, const Eigen::Vector3d* to, int n, const Eigen::Isometry3d& T,
                 double threshold_1m, bool* flags) {
  int count = 0;
  for (int i = 0; i < n; ++i) {
    const double depth = std::max(1.0, to[i].z());
    const double threshold = threshold_1m * depth * depth;
    flags[i] = (T * from[i] - to[i]).squaredNorm() < threshold * threshold;
    count += flags[i];
  }
  return count;
}

}  // namespace

int rigidRansac(const Eigen::Vector3d* from, const Eigen::Vector3d* to, int n,
                const RigidRansacOptions& options, bool* scratch, bool* inliers,
                Eigen::Isometry3d* T_to_from) {
  if (n < 3) return 0;
  std::mt19937 rng(options.seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  int best = 0;
  Eigen::Isometry3d best_T = Eigen::Isometry3d::Identity();
  for (int it = 0; it < options.iterations; ++it) {
    const int a = pick(rng), b = pick(rng), c = pick(rng);
    if (a == b || a == c || b == c) continue;
    // Nearly collinear samples give an ill-defined rotation.
    if ((to[b] - to[a]).cross(to[c] - to[a]).norm() < 1e-4) continue;
    const Eigen::Vector3d f[3] = {from[a], from[b], from[c]};
    const Eigen::Vector3d t[3] = {to[a], to[b], to[c]};
    Eigen::Isometry3d T;
    if (!rigidFitKabsch(f, t, nullptr, 3, &T)) continue;
    const int count = countInliers(from, to, n, T, options.inlier_threshold_m, scratch);
    if (count > best) {
      best = count;
      best_T = T;
      std::copy(scratch, scratch + n, inliers);
    }
  }
  if (best < 3) return 0;
  if (!rigidFitKabsch(from, to, inliers, n, &best_T)) return 0;
  *T_to_from = best_T;
  return countInliers(from, to, n, best_T, options.inlier_threshold_m, inliers);
}

}  // namespace plumb

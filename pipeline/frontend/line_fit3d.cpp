#include "pipeline/frontend/line_fit3d.h"

#include <Eigen/Eigenvalues>

namespace plumb {
namespace {

// Marks inliers of the line (point, dir); returns the count and the squared residual sum.
int markInliers(const Eigen::Vector3f* points, const float* thresholds, int count, const Eigen::Vector3f& point,
                const Eigen::Vector3f& dir, std::array<bool, kMaxLineSamples>& inlier, float* residual) {
  int n = 0;
  *residual = 0;
  for (int i = 0; i < count; ++i) {
    const float d = distanceToLine(points[i], point, dir);
    inlier[i] = d < thresholds[i];
    if (inlier[i]) {
      ++n;
      *residual += d * d;
    }
  }
  return n;
}

// Least squares: centroid and the eigenvector of the largest scatter eigenvalue.
bool refit(const Eigen::Vector3f* points, const std::array<bool, kMaxLineSamples>& inlier, int count,
           Eigen::Vector3f* point, Eigen::Vector3f* dir) {
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  int n = 0;
  for (int i = 0; i < count; ++i) {
    if (inlier[i]) {
      centroid += points[i];
      ++n;
    }
  }
  if (n < 2) return false;
  centroid /= static_cast<float>(n);
  Eigen::Matrix3f scatter = Eigen::Matrix3f::Zero();
  for (int i = 0; i < count; ++i) {
    if (inlier[i]) scatter += (points[i] - centroid) * (points[i] - centroid).transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> eig(scatter);
  *point = centroid;
  *dir = eig.eigenvectors().col(2).normalized();  // eigenvalues ascending
  return true;
}

}  // namespace

Line3dFit fitLine3dRobust(const Eigen::Vector3f* points, const float* thresholds, int count, int min_inliers) {
  Line3dFit fit;
  if (count < 2 || count > static_cast<int>(kMaxLineSamples)) return fit;
  int best_count = 0;
  float best_residual = 0;
  std::array<bool, kMaxLineSamples> inlier{};
  for (int i = 0; i < count; ++i) {
    for (int j = i + 1; j < count; ++j) {
      const Eigen::Vector3f d = points[j] - points[i];
      const float length = d.norm();
      if (length < 1e-6f) continue;
      float residual = 0;
      const int n = markInliers(points, thresholds, count, points[i], d / length, inlier, &residual);
      if (n > best_count || (n == best_count && residual < best_residual)) {
        best_count = n;
        best_residual = residual;
        fit.inlier = inlier;
      }
    }
  }
  if (best_count < 2) return fit;
  Eigen::Vector3f point, dir;
  if (!refit(points, fit.inlier, count, &point, &dir)) return fit;
  float residual = 0;
  const int refit_count = markInliers(points, thresholds, count, point, dir, inlier, &residual);
  if (refit_count >= best_count) {  // the refit can only be accepted if it loses nothing
    fit.inlier = inlier;
    best_count = refit_count;
    refit(points, fit.inlier, count, &point, &dir);
  }
  fit.point = point;
  fit.direction = dir;
  fit.num_inliers = best_count;
  fit.ok = best_count >= min_inliers;
  return fit;
}

}  // namespace plumb

#include "drivers/trajectory/rigid_alignment.h"

#include <Eigen/SVD>

namespace plumb {

Status alignRigid(const std::vector<Eigen::Vector3d>& p_source, const std::vector<Eigen::Vector3d>& p_target,
                  Eigen::Isometry3d* T_target_source) {
  if (p_source.size() != p_target.size())
    return Status::Error("rigid alignment: point counts differ (" + std::to_string(p_source.size()) + " vs " +
                         std::to_string(p_target.size()) + ")");
  const std::size_t n = p_source.size();
  if (n < 3) return Status::Error("rigid alignment: needs at least 3 point pairs, got " + std::to_string(n));

  Eigen::Vector3d mean_source = Eigen::Vector3d::Zero(), mean_target = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    mean_source += p_source[i];
    mean_target += p_target[i];
  }
  mean_source /= static_cast<double>(n);
  mean_target /= static_cast<double>(n);

  // Cross-covariance of the centred sets; its SVD gives the rotation that best maps source
  // directions onto target directions (Umeyama 1991, eq. 38-40 without scale).
  Eigen::Matrix3d cross_covariance = Eigen::Matrix3d::Zero();
  double source_spread = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d s = p_source[i] - mean_source;
    cross_covariance += (p_target[i] - mean_target) * s.transpose();
    source_spread += s.squaredNorm();
  }
  if (!(source_spread > 1e-18))
    return Status::Error("rigid alignment: degenerate points (all at one position)");

  Eigen::JacobiSVD<Eigen::Matrix3d> svd(cross_covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  // A reflection (det = -1) fits mirrored data better but is not a rotation: flip the axis of the
  // smallest singular value instead.
  Eigen::Matrix3d reflection_guard = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0) reflection_guard(2, 2) = -1;
  const Eigen::Matrix3d R_target_source = svd.matrixU() * reflection_guard * svd.matrixV().transpose();

  T_target_source->setIdentity();
  T_target_source->linear() = R_target_source;
  T_target_source->translation() = mean_target - R_target_source * mean_source;
  return Status::Ok();
}

}  // namespace plumb

#include "drivers/trajectory/rigid_alignment.h"

#include "solver/rigid_fit.h"

namespace plumb {

Status alignRigid(const std::vector<Eigen::Vector3d>& p_source, const std::vector<Eigen::Vector3d>& p_target,
                  Eigen::Isometry3d* T_target_source) {
  if (p_source.size() != p_target.size())
    return Status::Error("rigid alignment: point counts differ (" + std::to_string(p_source.size()) + " vs " +
                         std::to_string(p_target.size()) + ")");
  const std::size_t n = p_source.size();
  if (n < 3) return Status::Error("rigid alignment: needs at least 3 point pairs, got " + std::to_string(n));

  // A degenerate set (all at one position) has no rotation to find.
  Eigen::Vector3d mean_source = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : p_source) mean_source += p;
  mean_source /= static_cast<double>(n);
  double source_spread = 0;
  for (const Eigen::Vector3d& p : p_source) source_spread += (p - mean_source).squaredNorm();
  if (!(source_spread > 1e-18))
    return Status::Error("rigid alignment: degenerate points (all at one position)");
  // The tree's one least-squares rigid fit (solver/rigid_fit.h).
  if (!rigidFitKabsch(p_source.data(), p_target.data(), nullptr, int(n), T_target_source))
    return Status::Error("rigid alignment: no fit");
  return Status::Ok();
}

}  // namespace plumb

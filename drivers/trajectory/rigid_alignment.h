#pragma once
// Rigid (rotation + translation, no scale) least-squares alignment of two point sets, the
// closed form of Horn (1987) / Umeyama (1991) that the TUM benchmark's evaluate_ate uses:
//   T_target_source = argmin sum_i |p_target_i - T * p_source_i|^2
// via the SVD of the 3x3 cross-covariance, with the reflection guard of Umeyama (solver/rigid_fit.h).
#include <Eigen/Geometry>
#include <vector>

#include "platform/status.h"

namespace plumb {

// Needs >= 3 pairs (equal counts); error if the points are degenerate (all coincident).
Status alignRigid(const std::vector<Eigen::Vector3d>& p_source, const std::vector<Eigen::Vector3d>& p_target,
                  Eigen::Isometry3d* T_target_source);

}  // namespace plumb

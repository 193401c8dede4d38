#pragma once
// Rigid (rotation + translation, no scale) 3D-3D fits, the one implementation for the whole tree:
//   rigidFitKabsch  least squares over point pairs (Kabsch / Horn / Umeyama without scale: the SVD
//                   of the 3x3 cross-covariance with the reflection guard), e.g. the ATE alignment
//                   of drivers/trajectory/rigid_alignment.cpp (the TUM benchmark's evaluate_ate);
//   rigidRansac     RANSAC over minimal 3-point fits refitted on the inliers, for matched points
//                   that both have depth: loop verification (pipeline/loop/loop_verifier.cpp) and
//                   relocalization (pipeline/odometry/relocalizer.cpp).
// Fixed-size maths only: no heap allocation. Deterministic: the sampler is seeded from the options
// on every call.
#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace plumb {

struct RigidRansacOptions {
  int iterations = 200;
  // Residual |T from - to| of an inlier at 1 m depth of `to`; scaled by depth^2 like the sensor noise.
  double inlier_threshold_m = 0.05;
  uint32_t seed = 1;
};

// Least-squares rigid transform mapping from[i] onto to[i] for the flagged pairs (all if flags is
// null). false when fewer than 3 pairs.
bool rigidFitKabsch(const Eigen::Vector3d* from, const Eigen::Vector3d* to, const bool* flags, int n,
                    Eigen::Isometry3d* T_to_from);

// Best T_to_from over random 3-point fits, refitted on its inliers; `inliers` (n entries) flags
// them. Returns the inlier count (0 on failure). `scratch` must hold n entries.
int rigidRansac(const Eigen::Vector3d* from, const Eigen::Vector3d* to, int n,
                const RigidRansacOptions& options, bool* scratch, bool* inliers,
                Eigen::Isometry3d* T_to_from);

}  // namespace plumb

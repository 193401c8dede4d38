#pragma once
// Rigid 3D-3D RANSAC over minimal 3-point fits (both ends have depth), for loop verification.
// Fixed-size maths only (Kabsch on 3x3 matrices): no heap allocation. Deterministic: the sampler
// is seeded from the options on every call. The relocalizer (pipeline/odometry/relocalizer.cpp)
// keeps its own copy of the same scheme; its refit uses Eigen::umeyama on dynamic matrices, and
// sharing this one would change its numerics (and so every trajectory that relocalizes).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

namespace plumb::loop {

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

}  // namespace plumb::loop

#pragma once
// Robust 3D line fit for line-guidance samples (paper V-D warns that line features sit on object
// edges where depth is noisy). With N <= kMaxLineSamples samples, trying every pair as a line
// hypothesis is cheaper and more reliable than random sampling: the hypothesis with most inliers
// (ties: smallest squared residual) wins, then a least-squares refit (centroid + principal axis)
// on its inliers, and the inliers are re-evaluated once against the refit.
// A sample is an inlier when its distance to the line is below its own threshold (callers scale
// it with the depth sigma of that sample, so far samples are allowed more).
#include <array>
#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pipeline/frontend/capacities.h"

namespace plumb {

struct Line3dFit {
  bool ok = false;             // at least min_inliers inliers
  Eigen::Vector3f point = Eigen::Vector3f::Zero();      // centroid of the inliers
  Eigen::Vector3f direction = Eigen::Vector3f::Zero();  // unit
  std::array<bool, kMaxLineSamples> inlier{};
  int num_inliers = 0;
};

// points[i] with per-sample inlier thresholds[i] (metres), count <= kMaxLineSamples.
Line3dFit fitLine3dRobust(const Eigen::Vector3f* points, const float* thresholds, int count, int min_inliers);

inline float distanceToLine(const Eigen::Vector3f& p, const Eigen::Vector3f& point, const Eigen::Vector3f& unit_dir) {
  return (p - point).cross(unit_dir).norm();
}

}  // namespace plumb

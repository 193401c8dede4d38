#pragma once
// Fixed-size Eigen types shared by the solver. Sizes are known at compile time everywhere in the
// hot paths (6 = pose tangent, 3 = landmark / [u, v, u_r] observation), so no MatrixXd there.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace plumb {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Matrix36d = Eigen::Matrix<double, 3, 6>;  // d(3-vector) / d(pose tangent)
using Matrix63d = Eigen::Matrix<double, 6, 3>;  // pose-landmark block of H
using Matrix26d = Eigen::Matrix<double, 2, 6>;
using Matrix23d = Eigen::Matrix<double, 2, 3>;
using RowVector6d = Eigen::Matrix<double, 1, 6>;

}  // namespace plumb

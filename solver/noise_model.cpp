#include "solver/noise_model.h"

#include <algorithm>
#include <cmath>

namespace plumb {

double pixelSigma(const NoiseModelOptions& options, int pyramid_level) {
  return options.pixel_sigma_level0 * std::pow(options.scale_factor, std::max(pyramid_level, 0));
}

double depthSigma(const NoiseModelOptions& options, double depth_m) {
  return std::max(options.depth_sigma_per_m2 * depth_m * depth_m, options.min_depth_sigma);
}

Eigen::Matrix3d stereoPointInformation(const NoiseModelOptions& options, const CameraIntrinsics& camera,
                                       int pyramid_level, double depth_m) {
  if (!(depth_m >= options.min_depth)) return Eigen::Matrix3d::Zero();
  const double sp2 = std::pow(pixelSigma(options, pyramid_level), 2);
  const double sd = depthSigma(options, depth_m);
  const double k = camera.bf / (depth_m * depth_m);  // d u_r / d d
  const double su2 = k * k * sd * sd;                // variance u_r gains from depth
  // Sigma = [sp2 0 sp2; 0 sp2 0; sp2 0 sp2 + su2]. Its inverse in closed form (det = sp2^2 su2):
  // u and u_r share the pixel noise, so the information couples them.
  Eigen::Matrix3d information;
  information << 1.0 / sp2 + 1.0 / su2, 0.0, -1.0 / su2,  //
      0.0, 1.0 / sp2, 0.0,                                //
      -1.0 / su2, 0.0, 1.0 / su2;
  return information;
}

Eigen::Matrix2d monoPointInformation(const NoiseModelOptions& options, int pyramid_level) {
  return Eigen::Matrix2d::Identity() / std::pow(pixelSigma(options, pyramid_level), 2);
}

double lineSampleInformation(const NoiseModelOptions& options, int pyramid_level) {
  return 1.0 / std::pow(pixelSigma(options, pyramid_level), 2);
}

Eigen::Matrix3d backProjectedPointCovariance(const NoiseModelOptions& options,
                                             const CameraIntrinsics& camera, double u, double v,
                                             double depth_m, int pyramid_level) {
  const double sp2 = std::pow(pixelSigma(options, pyramid_level), 2);
  const double sd = depthSigma(options, depth_m);
  Eigen::Matrix3d J;  // d [X, Y, Z] / d [u, v, d]
  J << depth_m / camera.fx, 0.0, (u - camera.cx) / camera.fx,  //
      0.0, depth_m / camera.fy, (v - camera.cy) / camera.fy,   //
      0.0, 0.0, 1.0;
  const Eigen::Vector3d variances(sp2, sp2, sd * sd);
  return J * variances.asDiagonal() * J.transpose();
}

}  // namespace plumb

#include "solver/noise_model.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace plumb {

namespace {

// scale_factor^level for the default scale factor, computed once with the same std::pow call: the
// front end asks for ~1,200 pixel sigmas a frame (stereoPointInformation and
// backProjectedPointCovariance per keypoint) and std::pow cost ~120 instructions each (issue 22).
constexpr int kTabulatedLevels = 32;
struct DefaultScalePowers {
  double scale_factor = NoiseModelOptions{}.scale_factor;
  std::array<double, kTabulatedLevels> power{};
  DefaultScalePowers() {
    for (int level = 0; level < kTabulatedLevels; ++level) power[std::size_t(level)] = std::pow(scale_factor, level);
  }
};

}  // namespace

double pixelSigma(const NoiseModelOptions& options, int pyramid_level) {
  const int level = std::max(pyramid_level, 0);
  static const DefaultScalePowers kDefault;
  // Equal values are equal bits here: the default (1.2) is neither zero nor NaN.
  if (level < kTabulatedLevels && options.scale_factor == kDefault.scale_factor) {
    return options.pixel_sigma_level0 * kDefault.power[std::size_t(level)];
  }
  return options.pixel_sigma_level0 * std::pow(options.scale_factor, level);
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

namespace {

// y = T z with y = [u, v, u - u_r]; T is its own inverse, so information_y = T^T information_z T
// and back the same way.
Eigen::Matrix3d disparityTransform() {
  Eigen::Matrix3d T = Eigen::Matrix3d::Identity();
  T(2, 0) = 1.0;
  T(2, 2) = -1.0;
  return T;
}

}  // namespace

Eigen::Matrix3d lineSampleAnchorInformation(const NoiseModelOptions& options, const CameraIntrinsics& camera,
                                            int pyramid_level, double depth_m, const Eigen::Vector2d& along,
                                            double depth_sigma_scale) {
  if (!(depth_m >= options.min_depth) || !(depth_sigma_scale > 0.0)) return Eigen::Matrix3d::Zero();
  const double sigma_pixel = pixelSigma(options, pyramid_level);
  // The disparity bf / d moves by bf / d^2 per metre of depth.
  const double sigma_disparity = depth_sigma_scale * depthSigma(options, depth_m) * camera.bf / (depth_m * depth_m);
  Eigen::Matrix3d information_y = Eigen::Matrix3d::Zero();  // y = [u, v, u - u_r]
  information_y.topLeftCorner<2, 2>() = along * along.transpose() / (sigma_pixel * sigma_pixel);
  information_y(2, 2) = 1.0 / (sigma_disparity * sigma_disparity);
  const Eigen::Matrix3d T = disparityTransform();
  return T.transpose() * information_y * T;
}

void splitStereoChi2(const Eigen::Matrix3d& information, const Eigen::Vector3d& e, double* pixel_chi2,
                     double* depth_chi2) {
  const Eigen::Matrix3d T = disparityTransform();
  const Eigen::Matrix3d information_y = T.transpose() * information * T;
  const Eigen::Vector3d e_y = T * e;
  *pixel_chi2 = e_y.head<2>().dot(information_y.topLeftCorner<2, 2>() * e_y.head<2>());
  *depth_chi2 = e_y(2) * e_y(2) * information_y(2, 2);
}

Eigen::Matrix3d scaleStereoInformation(const Eigen::Matrix3d& information, double pixel_scale, double depth_scale) {
  const Eigen::Vector3d d(std::sqrt(pixel_scale), std::sqrt(pixel_scale), std::sqrt(depth_scale));
  const Eigen::Matrix3d& I = information;
  // The model's information (stereoPointInformation) has +0 at (0,1), (1,0), (1,2), (2,1). Then
  // each entry of the products below is the sum of its terms with a nonzero factor of T (one or
  // two, so their order does not matter), plus terms 0 * x that only decide the sign of a zero
  // result: "+ 0.0" where one of them is +0 (a -0 sum becomes +0, anything else stays). Written
  // out, that is ~70 instead of ~230 instructions a stereo observation for the same bits as the
  // matrix form below (issue 22; tests/solver/variance_factor_test.cpp compares them bit for bit).
  // The structure, finite entries and positive finite scales are checked; otherwise the matrix form.
  const auto positive_zero = [](double x) { return x == 0.0 && !std::signbit(x); };
  if (positive_zero(I(0, 1)) && positive_zero(I(1, 0)) && positive_zero(I(1, 2)) && positive_zero(I(2, 1)) &&
      std::isfinite(I(0, 0) + I(0, 2) + I(1, 1) + I(2, 0) + I(2, 2)) && d(0) > 0.0 && d(2) > 0.0 &&
      std::isfinite(d(0)) && std::isfinite(d(2))) {
    // A = T^T I, P = A T (T^T I T, the disparity coordinates); its (0,1), (1,0), (1,2), (2,1) are +0.
    const double a00 = (I(0, 0) + I(2, 0)) + 0.0, a02 = (I(0, 2) + I(2, 2)) + 0.0, a11 = I(1, 1) + 0.0;
    const double a20 = -I(2, 0) + 0.0, a22 = -I(2, 2) + 0.0;
    const double p00 = a00 + a02, p02 = -a02 + 0.0, p11 = a11, p20 = a20 + a22, p22 = -a22 + 0.0;
    // Y = diag(d) P diag(d): the structural zeros stay +0 (d > 0).
    const double y00 = (d(0) * p00) * d(0), y02 = (d(0) * p02) * d(2), y11 = (d(1) * p11) * d(1);
    const double y20 = (d(2) * p20) * d(0), y22 = (d(2) * p22) * d(2);
    // B = T^T Y, then B T.
    const double b00 = (y00 + y20) + 0.0, b02 = (y02 + y22) + 0.0, b11 = y11 + 0.0;
    const double b20 = -y20 + 0.0, b22 = -y22 + 0.0;
    Eigen::Matrix3d out;
    out << b00 + b02, 0.0, -b02 + 0.0,  //
        0.0, b11, 0.0,                  //
        b20 + b22, 0.0, -b22 + 0.0;
    return out;
  }
  const Eigen::Matrix3d T = disparityTransform();
  const Eigen::Matrix3d information_y = d.asDiagonal() * (T.transpose() * information * T) * d.asDiagonal();
  return T.transpose() * information_y * T;
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

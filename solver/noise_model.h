#pragma once
// Measurement noise of the RGB-D front end and its propagation into information matrices
// (paper section V-D, eqs. 26-28).
//
// A keypoint is measured as pixel p_uv = [u, v] (sigma_p, from its pyramid level) and depth d
// (sigma_d, quadratic in d: the Kinect model of Khoshelham & Elberink / Smisek et al.). The
// observation used by the factors is z = [u, v, u_r] with u_r = u - bf / d, so
//
//   J = d z / d (u, v, d) = [ 1 0 0 ; 0 1 0 ; 1 0 bf/d^2 ]
//   Sigma_z = J diag(sp^2, sp^2, sd^2) J^T,      information = Sigma_z^-1   (closed form, below)
#include <Eigen/Core>

#include "solver/camera_intrinsics.h"

namespace plumb {

struct NoiseModelOptions {
  // Pixel sigma of a feature detected at pyramid level 0 [px]; ORB-SLAM2 uses 1 px.
  double pixel_sigma_level0 = 1.0;
  // Pyramid scale factor: sigma_p(level) = pixel_sigma_level0 * scale_factor^level (ORB: 1.2).
  double scale_factor = 1.2;
  // sigma_d = depth_sigma_per_m2 * d^2 [m]. 0.0015 /m fits the Kinect v1 / structured-light model
  // (Khoshelham 2012: ~1.5 mm at 1 m, ~4 cm at 5 m).
  double depth_sigma_per_m2 = 0.0015;
  // Floor on sigma_d [m] so very near points do not get absurd confidence.
  double min_depth_sigma = 0.001;
  // Depths below this [m] are treated as invalid by the helpers (they return a zero information).
  double min_depth = 0.05;
};

double pixelSigma(const NoiseModelOptions& options, int pyramid_level);
double depthSigma(const NoiseModelOptions& options, double depth_m);

// 3x3 information of z = [u, v, u_r] for a keypoint at `pyramid_level` with depth `depth_m`.
// Returns a zero matrix when depth_m < options.min_depth (the caller should then use the 2x2
// monocular information instead).
Eigen::Matrix3d stereoPointInformation(const NoiseModelOptions& options, const CameraIntrinsics& camera,
                                       int pyramid_level, double depth_m);

// 2x2 information of z = [u, v] for a keypoint without depth: I / sigma_p(level)^2.
Eigen::Matrix2d monoPointInformation(const NoiseModelOptions& options, int pyramid_level);

// Scalar information of a line-guidance residual e = l^T [u v 1] (a signed distance in pixels,
// l normalised): 1 / sigma_p(level)^2.
double lineSampleInformation(const NoiseModelOptions& options, int pyramid_level);

// 3x3 information of z = [u, v, u_r] for a line-guidance point in the keyframe that back-projected
// it (its anchor; docs/ODOMETRY.md "Line samples keep their depth"). The line residuals measure a
// sample only across its 2D lines, so without this its depth is whatever local BA leaves it at.
//   - depth: a keypoint's disparity information with sigma_d times depth_sigma_scale (line pixels
//     sit on object edges, where the depth is noisier: paper section V);
//   - pixel: only along the 2D line (unit image direction `along`), with a keypoint's pixel sigma.
//     Where on its line a sample sits is the sampler's choice, not a measurement: this pins the
//     slide along the 3D line that no residual sees (it gives the poses no information). Across
//     the line nothing: the anchor's line residual already measures that.
// Zero when depth_m < options.min_depth.
Eigen::Matrix3d lineSampleAnchorInformation(const NoiseModelOptions& options, const CameraIntrinsics& camera,
                                            int pyramid_level, double depth_m, const Eigen::Vector2d& along,
                                            double depth_sigma_scale);

// The stereo residual [u, v, u_r] in the coordinates of its two noise sources, [u, v] (corner
// detection) and the disparity u - u_r = bf / d (depth), where the model's information is block
// diagonal. Used by the variance components (solver/local_ba.h, docs/UNCERTAINTY.md).
// chi2 of the pixel part and of the depth part of residual e under `information` (their sum is
// e^T information e when the information is the model's; cross terms, if any, are left out).
void splitStereoChi2(const Eigen::Matrix3d& information, const Eigen::Vector3d& e, double* pixel_chi2,
                     double* depth_chi2);
// `information` with its pixel block scaled by pixel_scale and its disparity part by depth_scale
// (cross terms by their geometric mean, which keeps it positive semi-definite).
Eigen::Matrix3d scaleStereoInformation(const Eigen::Matrix3d& information, double pixel_scale, double depth_scale);

// Covariance (camera frame, m^2) of the 3D point back-projected from pixel (u, v) with depth d:
// P = [(u - cx) d / fx, (v - cy) d / fy, d], propagated from diag(sp^2, sp^2, sd^2).
Eigen::Matrix3d backProjectedPointCovariance(const NoiseModelOptions& options,
                                             const CameraIntrinsics& camera, double u, double v,
                                             double depth_m, int pyramid_level);

}  // namespace plumb

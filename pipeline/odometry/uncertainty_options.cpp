#include "pipeline/odometry/uncertainty_options.h"

#include <cmath>

namespace plumb {

std::string validate(const UncertaintyOptions& o) {
  const double values[] = {o.relative_floor_translation_m, o.relative_floor_rotation_rad,
                           o.tracked_floor_translation_m,  o.tracked_floor_rotation_rad,
                           o.timing_sigma_s,               o.timing_sigma_per_readout,
                           o.rolling_shutter_velocity_sigma_mps, o.rolling_shutter_rate_sigma_radps,
                           o.rolling_shutter_frame_share,  o.default_translation_sigma_m,
                           o.default_rotation_sigma_rad,   o.segment_translation_sigma_m,
                           o.segment_rotation_sigma_rad};
  for (double v : values) {
    if (!(std::isfinite(v) && v >= 0)) return "every sigma, floor and share must be finite and >= 0";
  }
  if (!(o.relative_scale > 0 && o.tracked_scale > 0 && o.loop_scale > 0 && o.motion_scale > 0 &&
        std::isfinite(o.relative_scale) && std::isfinite(o.tracked_scale) && std::isfinite(o.loop_scale) &&
        std::isfinite(o.motion_scale)))
    return "relative_scale, tracked_scale, motion_scale and loop_scale must be finite and > 0";
  if (!(o.default_translation_sigma_m > 0 && o.default_rotation_sigma_rad > 0 && o.segment_translation_sigma_m > 0 &&
        o.segment_rotation_sigma_rad > 0))
    return "the default and segment sigmas must be > 0 (they are chained as covariances)";
  if (!(o.max_published_translation_sigma_m > 0 && o.max_published_rotation_sigma_rad > 0 &&
        o.max_published_translation_sigma_m <= 1e6 && o.max_published_rotation_sigma_rad <= 1e6))
    return "max_published_translation_sigma_m and max_published_rotation_sigma_rad must be in (0, 1e6]";
  return "";
}

Eigen::Matrix<double, 6, 6> diagonalPoseCovariance(double sigma_translation_m, double sigma_rotation_rad) {
  Eigen::Matrix<double, 6, 1> d;
  d << Eigen::Vector3d::Constant(sigma_translation_m * sigma_translation_m),
      Eigen::Vector3d::Constant(sigma_rotation_rad * sigma_rotation_rad);
  return d.asDiagonal();
}

namespace {

Eigen::Matrix<double, 6, 6> inflate(const UncertaintyOptions& o, double scale, double floor_translation_m,
                                    double floor_rotation_rad, const Eigen::Matrix<double, 6, 6>& covariance,
                                    double variance_factor) {
  const double s = (o.use_variance_factor ? variance_factor : 1.0) * scale;
  return s * covariance + diagonalPoseCovariance(floor_translation_m, floor_rotation_rad);
}

}  // namespace

Eigen::Matrix<double, 6, 6> inflateRelativeCovariance(const UncertaintyOptions& o,
                                                      const Eigen::Matrix<double, 6, 6>& ba_relative,
                                                      double variance_factor) {
  return inflate(o, o.relative_scale, o.relative_floor_translation_m, o.relative_floor_rotation_rad, ba_relative,
                 variance_factor);
}

Eigen::Matrix<double, 6, 6> inflateTrackedCovariance(const UncertaintyOptions& o,
                                                     const Eigen::Matrix<double, 6, 6>& pose_only,
                                                     double variance_factor) {
  return inflate(o, o.tracked_scale, o.tracked_floor_translation_m, o.tracked_floor_rotation_rad, pose_only,
                 variance_factor);
}

Eigen::Matrix<double, 6, 6> inflateMotionCovariance(const UncertaintyOptions& o,
                                                    const Eigen::Matrix<double, 6, 6>& pose_only,
                                                    double variance_factor) {
  return inflate(o, o.motion_scale, o.tracked_floor_translation_m, o.tracked_floor_rotation_rad, pose_only,
                 variance_factor);
}

Eigen::Matrix<double, 6, 6> timingCovariance(const UncertaintyOptions& o, double readout_s,
                                             const Eigen::Matrix<double, 6, 1>& twist_per_s) {
  const double sigma_t = o.timing_sigma_s + o.timing_sigma_per_readout * readout_s;
  return (sigma_t * sigma_t) * twist_per_s * twist_per_s.transpose();
}

Eigen::Matrix<double, 6, 6> rollingShutterCovariance(const UncertaintyOptions& o, double readout_s, double share) {
  return diagonalPoseCovariance(share * o.rolling_shutter_velocity_sigma_mps * readout_s,
                                share * o.rolling_shutter_rate_sigma_radps * readout_s);
}

}  // namespace plumb

// LocalBundleAdjuster::varianceFactor (solver/local_ba.h, solver/variance_factor.h).
#include <algorithm>

#include "solver/factors.h"
#include "solver/local_ba.h"
#include "solver/noise_model.h"
#include "solver/variance_factor.h"

namespace plumb {

bool LocalBundleAdjuster::isLineSample(const Landmark& landmark) const {
  for (int k = 0; k < landmark.num_observations; ++k) {
    if (observations_[observation_order_[landmark.first_observation + k]].kind == ObservationKind::kLineSample) return true;
  }
  return false;
}

double LocalBundleAdjuster::varianceFactor(const LocalBaOptions& options) const {
  InlierChi2Sums sums;
  double parameters = 6.0 * num_pose_variables_;
  for (int l = 0; l < num_landmarks_; ++l) {
    const Landmark& landmark = landmarks_[l];
    int dof = 0;
    bool line_sample = false, anchored = false;
    for (int k = 0; k < landmark.num_observations; ++k) {
      const Observation& obs = observations_[observation_order_[landmark.first_observation + k]];
      if (!obs.enabled || obs.outlier) continue;
      const int obs_dof = obs.kind == ObservationKind::kStereoPoint ? 3 : obs.kind == ObservationKind::kMonoPoint ? 2 : 1;
      line_sample = line_sample || obs.kind == ObservationKind::kLineSample;
      anchored = anchored || obs.kind != ObservationKind::kLineSample;
      sums.add(obs_dof, obs.chi2);
      dof += obs_dof;
    }
    // A line sample's slide along its line is unobservable unless its anchor pins it.
    parameters += std::min(dof, line_sample && !anchored ? 2 : 3);
  }
  return plumb::varianceFactor(sums, parameters, options.chi2);
}

PointVarianceComponents LocalBundleAdjuster::varianceComponents(const LocalBaOptions& options,
                                                                int min_redundancy) const {
  // Each part is summed as a chi-square of its own dof (pixel 2, depth 1), truncated where the
  // whole observation was (an inlier's total chi2 is below its threshold).
  InlierChi2Sums pixel, depth;
  double parameters = 6.0 * num_pose_variables_;
  for (int l = 0; l < num_landmarks_; ++l) {
    const Landmark& landmark = landmarks_[l];
    if (isLineSample(landmark)) continue;  // its anchor's residual is not a point's either
    int dof = 0;
    for (int k = 0; k < landmark.num_observations; ++k) {
      const Observation& obs = observations_[observation_order_[landmark.first_observation + k]];
      if (!obs.enabled || obs.outlier) continue;
      if (obs.kind == ObservationKind::kMonoPoint) {
        pixel.add(2, obs.chi2);
        dof += 2;
        continue;
      }
      Eigen::Vector3d e;
      if (!evaluateStereoPoint(camera_, keyframes_[obs.keyframe].T_cam_world, landmark.P_world, obs.z, &e, nullptr,
                               nullptr))
        continue;
      double pixel_chi2 = 0, depth_chi2 = 0;
      splitStereoChi2(obs.information, e, &pixel_chi2, &depth_chi2);
      pixel.add(2, pixel_chi2);
      depth.add(1, depth_chi2);
      dof += 3;
    }
    parameters += std::min(dof, 3);
  }
  PointVarianceComponents out;
  const double n_pixel = pixel.errorDof(), n_depth = depth.errorDof();
  const double n = n_pixel + n_depth;
  out.redundancy = n - parameters;
  if (!(n > 0)) return out;
  // Both parts were truncated at the stereo threshold (mono points: theirs, close enough here).
  OutlierChi2 thresholds = options.chi2;
  thresholds.mono = thresholds.stereo;
  thresholds.line = thresholds.stereo;
  auto component = [&](const InlierChi2Sums& sums, double share) {
    const double redundancy = out.redundancy * share;
    return plumb::varianceFactor(sums, sums.errorDof() - redundancy, thresholds, min_redundancy);
  };
  out.pixel = component(pixel, n_pixel / n);
  out.depth = component(depth, n_depth / n);
  return out;
}

}  // namespace plumb

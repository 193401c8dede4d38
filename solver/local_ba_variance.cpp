// LocalBundleAdjuster::varianceFactor (solver/local_ba.h, solver/variance_factor.h).
#include <algorithm>

#include "solver/local_ba.h"
#include "solver/variance_factor.h"

namespace plumb {

double LocalBundleAdjuster::varianceFactor(const LocalBaOptions& options) const {
  InlierChi2Sums sums;
  double parameters = 6.0 * num_pose_variables_;
  for (int l = 0; l < num_landmarks_; ++l) {
    const Landmark& landmark = landmarks_[l];
    int dof = 0, max_rank = 3;
    for (int k = 0; k < landmark.num_observations; ++k) {
      const Observation& obs = observations_[observation_order_[landmark.first_observation + k]];
      if (!obs.enabled || obs.outlier) continue;
      const int obs_dof = obs.kind == ObservationKind::kStereoPoint ? 3 : obs.kind == ObservationKind::kMonoPoint ? 2 : 1;
      if (obs.kind == ObservationKind::kLineSample) max_rank = 2;
      sums.add(obs_dof, obs.chi2);
      dof += obs_dof;
    }
    parameters += std::min(dof, max_rank);
  }
  return plumb::varianceFactor(sums, parameters, options.chi2);
}

}  // namespace plumb

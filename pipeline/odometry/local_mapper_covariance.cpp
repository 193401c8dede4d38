// LocalMapper: the uncertainty a keyframe publishes (pipeline/odometry/keyframe_uncertainty.h)
// from the joint marginal of a local BA (solver/pose_covariance.h, docs/UNCERTAINTY.md).
#include "pipeline/odometry/local_mapper.h"
#include "solver/pose_covariance.h"
#include "solver/se3_jacobians.h"

namespace plumb {

bool LocalMapper::publishable(const Matrix6d& covariance) {
  const UncertaintyOptions& u = options_.uncertainty;
  if (publishablePoseCovariance(covariance, u.max_published_translation_sigma_m, u.max_published_rotation_sigma_rad))
    return true;
  ++stats_.ba_covariances_refused;
  return false;
}

int LocalMapper::previousKeyframeSlot(uint32_t id) const {
  int previous = -1;
  for (int s = 0; s < int(kMaxMapKeyframes); ++s) {
    if (!map_.keyframeAlive(s)) continue;
    const uint32_t other = map_.keyframe(s).id;
    if (other < id && (previous < 0 || other > map_.keyframe(previous).id)) previous = s;
  }
  return previous;
}

void LocalMapper::writeUncertainty(int kf_slot, bool have_covariance, double variance_factor) {
  const UncertaintyOptions& u = options_.uncertainty;
  const double readout_s = camera_.rolling_shutter_readout_s;
  // Joint marginal blocks of a BA keyframe (zero for fixed ones: they are the gauge).
  auto block = [this](int index_a, int index_b) -> Matrix6d {
    const int a = ba_.poseVariableIndex(index_a), b = ba_.poseVariableIndex(index_b);
    if (a < 0 || b < 0) return Matrix6d::Zero();
    return ba_.fullCovariance().block<6, 6>(6 * a, 6 * b);
  };
  Keyframe& kf = map_.keyframe(kf_slot);
  const int kf_previous = previousKeyframeSlot(kf.id);
  // The new keyframe's relative covariance without the timing term, for chaining: a timing error
  // of one keyframe displaces its own stamped pose, not the map the next ones are tracked in.
  Matrix6d chain_relative = defaultRelativeCovariance(u);
  if (have_covariance) {
    for (int slot : s_->window) {
      const int previous = previousKeyframeSlot(map_.keyframe(slot).id);
      if (previous < 0) continue;
      const int i = s_->ba_keyframe_index[previous], j = s_->ba_keyframe_index[slot];
      if (i < 0) continue;  // the previous keyframe was not in this BA: keep the last relative
      const Eigen::Isometry3d& T_i = ba_.pose(i);
      const Eigen::Isometry3d& T_j = ba_.pose(j);
      const Keyframe& p = map_.keyframe(previous);
      KeyframeUncertainty& out = map_.keyframe(slot).uncertainty;
      const Matrix6d A = adjointSE3(T_j * T_i.inverse());
      const Matrix6d rolling_shutter = rollingShutterCovariance(u, readout_s);
      const Matrix6d ba_relative = inflateRelativeCovariance(
          u, relativePoseCovariance(T_i, T_j, block(i, i), block(j, j), block(i, j)), variance_factor);
      if (!publishable(ba_relative)) continue;  // keep the last relative (and chain the default)
      // Chained: each keyframe adds its own rolling-shutter error once (it shapes the landmarks made
      // from it, so it stays in the map); the relative pose sees the errors of both ends.
      if (slot == kf_slot) chain_relative = ba_relative + rolling_shutter;
      const Matrix6d relative = ba_relative + A * rolling_shutter * A.transpose() + rolling_shutter;
      // Timing errors of both ends: d_i = twist_i dt_i enters e as Ad(T_j_i) d_i, d_j as -d_j.
      out.previous_id = p.id;
      out.previous_timestamp_s = p.timestamp_s;
      out.T_previous_this = T_i * T_j.inverse();
      out.relative_covariance = relative + A * timingCovariance(u, readout_s, p.uncertainty.twist_per_s) * A.transpose() +
                                timingCovariance(u, readout_s, out.twist_per_s);
    }
  }
  // The new keyframe's world covariance: its previous keyframe's, chained.
  if (kf_previous < 0) return;
  const Keyframe& p = map_.keyframe(kf_previous);
  if (!p.uncertainty.world_covariance_valid) return;
  kf.uncertainty.world_covariance = chainPoseCovariance(p.T_world_cam.inverse(), kf.T_world_cam.inverse(),
                                                        p.uncertainty.world_covariance, chain_relative);
  kf.uncertainty.world_covariance_valid = true;
}

}  // namespace plumb

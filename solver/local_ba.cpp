// LocalBundleAdjuster, problem set-up: reserved storage, adding keyframes / landmarks /
// observations, the landmark-major observation order, and result accessors.
#include <algorithm>

#include "solver/finite_check.h"
#include "solver/local_ba.h"

namespace plumb {

const char* toString(LocalBaStatus status) {
  switch (status) {
    case LocalBaStatus::kConverged:
      return "converged";
    case LocalBaStatus::kMaxIterations:
      return "max iterations";
    case LocalBaStatus::kNoVariables:
      return "no variables";
    case LocalBaStatus::kLinearSolverFailed:
      return "reduced camera system not positive definite";
  }
  return "unknown";
}

void LocalBundleAdjuster::reserve(int max_keyframes, int max_landmarks, int max_observations) {
  keyframes_.resize(std::max(max_keyframes, 0));
  landmarks_.resize(std::max(max_landmarks, 0));
  observations_.resize(std::max(max_observations, 0));
  observation_order_.resize(observations_.size());
  landmark_scratch_.resize(observations_.size());
  landmark_scratch_obs_.resize(observations_.size());
  landmark_scratch_u_.resize(observations_.size());
  variable_keyframe_.resize(keyframes_.size());
  const Eigen::Index max_dim = 6 * static_cast<Eigen::Index>(keyframes_.size());
  S_.setZero(max_dim, max_dim);
  rhs_.setZero(max_dim);
  covariance_.setZero(max_dim, max_dim);
  clear();
}

void LocalBundleAdjuster::clear() {
  num_keyframes_ = 0;
  num_landmarks_ = 0;
  num_observations_ = 0;
  num_pose_variables_ = 0;
  num_fixed_landmarks_ = 0;
  covariance_valid_ = false;
  linearized_at_estimate_ = false;
  structure_built_ = false;
}

int LocalBundleAdjuster::addKeyframe(const Eigen::Isometry3d& T_cam_world, bool fixed) {
  if (num_keyframes_ >= static_cast<int>(keyframes_.size()) || !T_cam_world.matrix().allFinite()) return -1;
  Keyframe& kf = keyframes_[num_keyframes_];
  kf.T_cam_world = T_cam_world;
  kf.step.setZero();
  kf.variable = fixed ? -1 : num_pose_variables_;
  if (!fixed) variable_keyframe_[num_pose_variables_++] = num_keyframes_;
  covariance_valid_ = false;
  linearized_at_estimate_ = false;
  return num_keyframes_++;
}

int LocalBundleAdjuster::addLandmark(const Eigen::Vector3d& P_world) {
  if (num_landmarks_ >= static_cast<int>(landmarks_.size()) || !P_world.allFinite()) return -1;
  Landmark& lm = landmarks_[num_landmarks_];
  lm.P_world = P_world;
  lm.step.setZero();
  lm.eliminated = false;
  linearized_at_estimate_ = false;
  structure_built_ = false;
  return num_landmarks_++;
}

int LocalBundleAdjuster::addObservation(int keyframe, int landmark, ObservationKind kind,
                                        const Eigen::Vector3d& z, const Eigen::Matrix3d& information) {
  if (num_observations_ >= static_cast<int>(observations_.size())) return -1;
  if (keyframe < 0 || keyframe >= num_keyframes_ || landmark < 0 || landmark >= num_landmarks_) return -1;
  // Non-finite input would poison the whole solve: z.allFinite() && information.allFinite(), as
  // one test of the two residues' sum (finite_check.h; +0 only when every entry is finite).
  if (!(finiteResidue(z.data(), 3) + finiteResidue(information.data(), 9) == 0.0)) return -1;
  Observation& obs = observations_[num_observations_];
  obs.keyframe = keyframe;
  obs.landmark = landmark;
  obs.kind = kind;
  obs.z = z;
  obs.information = information;
  obs.enabled = true;
  obs.valid = false;
  obs.outlier = false;
  obs.chi2 = 0.0;
  linearized_at_estimate_ = false;
  structure_built_ = false;
  return num_observations_++;
}

int LocalBundleAdjuster::addStereoPointObservation(int keyframe, int landmark, const Eigen::Vector3d& z_uvr,
                                                   const Eigen::Matrix3d& information) {
  return addObservation(keyframe, landmark, ObservationKind::kStereoPoint, z_uvr, information);
}

int LocalBundleAdjuster::addMonoPointObservation(int keyframe, int landmark, const Eigen::Vector2d& z_uv,
                                                 const Eigen::Matrix2d& information) {
  Eigen::Matrix3d info3 = Eigen::Matrix3d::Zero();
  info3.topLeftCorner<2, 2>() = information;
  return addObservation(keyframe, landmark, ObservationKind::kMonoPoint, Eigen::Vector3d(z_uv.x(), z_uv.y(), 0.0),
                        info3);
}

int LocalBundleAdjuster::addLineObservation(int keyframe, int landmark, const Eigen::Vector3d& line,
                                            double information) {
  Eigen::Matrix3d info3 = Eigen::Matrix3d::Zero();
  info3(0, 0) = information;
  return addObservation(keyframe, landmark, ObservationKind::kLineSample, line, info3);
}

void LocalBundleAdjuster::setObservationEnabled(int observation, bool enabled) {
  if (observation < 0 || observation >= num_observations_) return;
  observations_[observation].enabled = enabled;
  linearized_at_estimate_ = false;
}

// Groups observation indices by landmark (counting sort into the reserved order array).
void LocalBundleAdjuster::buildStructure() {
  // The order is a function of the landmarks' and observations' count and of each observation's
  // landmark: built once after the last addition (solve() and computeCovariance() both ask).
  if (structure_built_) return;
  structure_built_ = true;
  for (int j = 0; j < num_landmarks_; ++j) landmarks_[j].num_observations = 0;
  for (int k = 0; k < num_observations_; ++k) ++landmarks_[observations_[k].landmark].num_observations;
  int offset = 0;
  for (int j = 0; j < num_landmarks_; ++j) {
    landmarks_[j].first_observation = offset;
    offset += landmarks_[j].num_observations;
    landmarks_[j].num_observations = 0;
  }
  for (int k = 0; k < num_observations_; ++k) {
    Landmark& lm = landmarks_[observations_[k].landmark];
    observation_order_[lm.first_observation + lm.num_observations++] = k;
  }
}

Matrix6d LocalBundleAdjuster::covariance(int keyframe) const {
  const int v = keyframes_[keyframe].variable;
  if (!covariance_valid_ || v < 0) return Matrix6d::Zero();
  return covariance_.block<6, 6>(6 * v, 6 * v);
}

Eigen::Block<const Eigen::MatrixXd> LocalBundleAdjuster::fullCovariance() const {
  const Eigen::MatrixXd& covariance = covariance_;
  const Eigen::Index dim = covariance_valid_ ? 6 * static_cast<Eigen::Index>(num_pose_variables_) : 0;
  return covariance.topLeftCorner(dim, dim);
}

Vector6d LocalBundleAdjuster::poseStep(int keyframe) const { return keyframes_[keyframe].step; }

Eigen::Vector3d LocalBundleAdjuster::landmarkStep(int landmark) const { return landmarks_[landmark].step; }

}  // namespace plumb

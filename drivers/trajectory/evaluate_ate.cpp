#include "drivers/trajectory/evaluate.h"
#include "drivers/trajectory/rigid_alignment.h"

namespace plumb {

Status evaluateAte(const std::vector<StampedPose>& ground_truth, const std::vector<StampedPose>& estimate,
                   const AteOptions& options, AteResult* out) {
  std::vector<const StampedPose*> gt_poses, est_poses;
  std::vector<double> gt_stamps, est_stamps;
  for (const StampedPose& p : ground_truth) {
    if (!p.valid) continue;
    gt_poses.push_back(&p);
    gt_stamps.push_back(p.timestamp);
  }
  for (const StampedPose& p : estimate) {
    if (!p.valid) continue;
    est_poses.push_back(&p);
    est_stamps.push_back(p.timestamp);
  }
  // evaluate_ate associates (ground truth, estimate) in that order; the order matters for ties.
  const std::vector<IndexPair> pairs = associateTimestamps(gt_stamps, est_stamps, options.association);
  if (pairs.size() < 3)
    return Status::Error("ATE: only " + std::to_string(pairs.size()) +
                         " estimate poses lie within the association window of a ground-truth "
                         "pose (need >= 3); do the timestamps belong to the same sequence?");

  std::vector<Eigen::Vector3d> p_world_gt, p_world_est;
  for (const IndexPair& pair : pairs) {
    p_world_gt.push_back(gt_poses[pair.first]->T_world_cam.translation());
    p_world_est.push_back(est_poses[pair.second]->T_world_cam.translation());
  }
  AteResult result;
  PLUMB_RETURN_IF_ERROR(alignRigid(p_world_est, p_world_gt, &result.T_gt_est).withContext("ATE"));

  std::vector<double> errors;
  errors.reserve(pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    AteSample sample;
    sample.timestamp_s = gt_stamps[pairs[k].first];
    sample.p_world_gt = p_world_gt[k];
    sample.p_world_est_aligned = result.T_gt_est * p_world_est[k];
    errors.push_back((sample.p_world_est_aligned - sample.p_world_gt).norm());
    result.samples.push_back(sample);
  }
  result.pairs = pairs.size();
  result.translation_m = computeErrorStatistics(errors);
  *out = std::move(result);
  return Status::Ok();
}

}  // namespace plumb

#include <algorithm>
#include <cmath>

#include "drivers/trajectory/evaluate.h"

namespace plumb {
namespace {

// Index of the stamp closest to t (ties: the earlier one). `stamps` sorted, non-empty.
std::size_t closestIndex(const std::vector<double>& stamps, double t) {
  const auto it = std::lower_bound(stamps.begin(), stamps.end(), t);
  if (it == stamps.begin()) return 0;
  if (it == stamps.end()) return stamps.size() - 1;
  const std::size_t after = static_cast<std::size_t>(it - stamps.begin());
  return (*it - t) < (t - stamps[after - 1]) ? after : after - 1;
}

double medianInterval(const std::vector<double>& stamps) {
  std::vector<double> intervals;
  for (std::size_t i = 1; i < stamps.size(); ++i) intervals.push_back(stamps[i] - stamps[i - 1]);
  return computeErrorStatistics(intervals).median;
}

// The benchmark's arccos((trace - 1) / 2) loses ~1e-8 rad near zero; atan2 of the sine (from the
// skew part) and the cosine is the same angle without that cancellation.
double rotationAngleRad(const Eigen::Matrix3d& R) {
  const Eigen::Vector3d skew(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  return std::atan2(0.5 * skew.norm(), 0.5 * (R.trace() - 1.0));
}

}  // namespace

Status evaluateRpe(const std::vector<StampedPose>& ground_truth, const std::vector<StampedPose>& estimate,
                   const RpeOptions& options, RpeResult* out) {
  std::vector<const StampedPose*> gt, est;
  std::vector<double> gt_stamps, est_stamps;
  for (const StampedPose& p : ground_truth) {
    if (!p.valid) continue;
    gt.push_back(&p);
    gt_stamps.push_back(p.timestamp);
  }
  for (const StampedPose& p : estimate) {
    if (!p.valid) continue;
    est.push_back(&p);
    est_stamps.push_back(p.timestamp);
  }
  if (gt.size() < 2 || est.size() < 2) return Status::Error("RPE: needs at least 2 poses in each trajectory");

  // A ground-truth stamp further than two of its usual intervals away means a gap: skip the pair.
  const double gt_max_dt = 2.0 * medianInterval(gt_stamps);
  std::vector<double> translation_errors, rotation_errors_deg;
  for (std::size_t i = 0; i < est.size(); ++i) {
    const std::size_t j = closestIndex(est_stamps, est_stamps[i] + options.delta_s);
    // evaluate_rpe drops pairs ending on the last frame (that is also where t_i + delta overshoots).
    if (j == est.size() - 1) continue;
    const std::size_t gi = closestIndex(gt_stamps, est_stamps[i]);
    const std::size_t gj = closestIndex(gt_stamps, est_stamps[j]);
    if (std::abs(gt_stamps[gi] - est_stamps[i]) > gt_max_dt ||
        std::abs(gt_stamps[gj] - est_stamps[j]) > gt_max_dt)
      continue;
    const Eigen::Isometry3d T_esti_estj = est[i]->T_world_cam.inverse() * est[j]->T_world_cam;
    const Eigen::Isometry3d T_gti_gtj = gt[gi]->T_world_cam.inverse() * gt[gj]->T_world_cam;
    // Same composition order as evaluate_rpe's ominus(ominus(E_j, E_i), ominus(G_j, G_i)).
    const Eigen::Isometry3d error = T_esti_estj * T_gti_gtj.inverse();
    translation_errors.push_back(error.translation().norm());
    rotation_errors_deg.push_back(rotationAngleRad(error.linear()) * 180.0 / M_PI);
  }
  if (translation_errors.empty())
    return Status::Error("RPE: no estimate pose pair " + std::to_string(options.delta_s) +
                         " s apart has ground truth at both ends");
  out->pairs = translation_errors.size();
  out->translation_m_per_s = computeErrorStatistics(translation_errors);
  out->rotation_deg_per_s = computeErrorStatistics(rotation_errors_deg);
  return Status::Ok();
}

}  // namespace plumb

// Trajectory files and their evaluation through the public API: the drivers' reader, writer and
// evaluation (drivers/trajectory/), so the numbers are exactly `plumb eval`'s.
#include "api/api_convert.h"
#include "api/plumb/odometry.h"
#include "drivers/trajectory/evaluate.h"

namespace plumb::api {

Status readTrajectory(const std::string& path, std::vector<FinishedPose>* out) {
  std::vector<StampedPose> poses;
  TrajectoryReadOptions options;
  options.keep_lost_markers = true;
  const Status st = fromStatus(readTumTrajectory(path, &poses, options));
  if (!st.ok) return st;
  out->clear();
  for (std::size_t i = 0; i < poses.size(); ++i) {
    out->push_back(toFinished(poses[i]));
    out->back().sequence = i;
  }
  return Status::Ok();
}

Status writeTrajectory(const std::string& path, const std::vector<FinishedPose>& poses) {
  std::vector<StampedPose> stamped;
  stamped.reserve(poses.size());
  for (const FinishedPose& p : poses) stamped.push_back(toStamped(p));
  return fromStatus(writeTumTrajectory(path, stamped));
}

namespace {

ErrorStats toStats(const ErrorStatistics& s) { return {s.rmse, s.mean, s.median, s.min, s.max}; }

// `plumb eval` reads files without their lost markers: the evaluation sees valid poses only.
std::vector<StampedPose> validPoses(const std::vector<FinishedPose>& poses) {
  std::vector<StampedPose> out;
  for (const FinishedPose& p : poses) {
    if (p.valid) out.push_back(toStamped(p));
  }
  return out;
}

}  // namespace

Evaluation evaluate(const std::vector<FinishedPose>& ground_truth, const std::vector<FinishedPose>& estimate) {
  const std::vector<StampedPose> gt = validPoses(ground_truth), est = validPoses(estimate);
  Evaluation e;
  AteResult ate;
  const ::plumb::Status ate_status = evaluateAte(gt, est, AteOptions{}, &ate);
  e.ate_valid = ate_status.ok();
  if (e.ate_valid) {
    e.ate_pairs = ate.pairs;
    e.ate_m = toStats(ate.translation_m);
  } else {
    e.ate_error = ate_status.message();
  }
  RpeResult rpe;
  const ::plumb::Status rpe_status = evaluateRpe(gt, est, RpeOptions{}, &rpe);
  e.rpe_valid = rpe_status.ok();
  if (e.rpe_valid) {
    e.rpe_pairs = rpe.pairs;
    e.rpe_m_per_s = toStats(rpe.translation_m_per_s);
    e.rpe_deg_per_s = toStats(rpe.rotation_deg_per_s);
  } else {
    e.rpe_error = rpe_status.message();
  }
  return e;
}

}  // namespace plumb::api

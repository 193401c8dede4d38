#include "drivers/trajectory/evaluate_nees.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

#include "solver/pose_covariance.h"
#include "solver/se3.h"

namespace plumb {
namespace {

constexpr double kChi2Dof6Quantile95 = 12.591587;

// Per-sample terms collected for one quantity.
struct Samples {
  std::vector<double> nees;
  double translation = 0, rotation = 0;          // sums of the 3-dof block NEES
  double e_t2 = 0, e_r2 = 0, sigma_t2 = 0, sigma_r2 = 0;  // sums of squares (errors, traces)
  std::size_t skipped = 0;

  void add(const Vector6d& e, const Matrix6d& C) {
    const double full = normalizedErrorSquared(e, C);
    if (!std::isfinite(full)) return;  // a singular covariance claims nothing checkable
    nees.push_back(full);
    const Eigen::Matrix3d Ct = C.topLeftCorner<3, 3>(), Cr = C.bottomRightCorner<3, 3>();
    translation += e.head<3>().dot(Ct.ldlt().solve(e.head<3>()));
    rotation += e.tail<3>().dot(Cr.ldlt().solve(e.tail<3>()));
    e_t2 += e.head<3>().squaredNorm();
    e_r2 += e.tail<3>().squaredNorm();
    sigma_t2 += Ct.trace();
    sigma_r2 += Cr.trace();
  }

  NeesStatistics statistics() const {
    NeesStatistics s;
    s.count = nees.size();
    s.skipped_no_truth = skipped;
    if (nees.empty()) return s;
    const double n = double(nees.size());
    double sum = 0;
    std::size_t inside = 0;
    for (double v : nees) {
      sum += v;
      inside += v <= kChi2Dof6Quantile95 ? 1 : 0;
    }
    std::vector<double> sorted = nees;
    std::sort(sorted.begin(), sorted.end());
    const std::size_t m = sorted.size() / 2;
    const double median = sorted.size() % 2 ? sorted[m] : 0.5 * (sorted[m - 1] + sorted[m]);
    s.mean_per_dof = sum / n / 6.0;
    s.median_per_dof = median / 6.0;
    s.translation_mean_per_dof = translation / n / 3.0;
    s.rotation_mean_per_dof = rotation / n / 3.0;
    s.inside_95 = double(inside) / n;
    s.rmse_translation_m = std::sqrt(e_t2 / n);
    s.rmse_rotation_deg = std::sqrt(e_r2 / n) * kDegreesPerRadian;
    s.rms_sigma_translation_m = std::sqrt(sigma_t2 / n);
    s.rms_sigma_rotation_deg = std::sqrt(sigma_r2 / n) * kDegreesPerRadian;
    return s;
  }
};

}  // namespace

bool interpolatePose(const std::vector<StampedPose>& gt, double t, double max_gap_s, Eigen::Isometry3d* T) {
  const auto after = std::lower_bound(gt.begin(), gt.end(), t,
                                      [](const StampedPose& p, double time) { return p.timestamp < time; });
  if (after == gt.end()) return false;
  if (after->timestamp == t) {
    if (!after->valid) return false;
    *T = after->T_world_cam;
    return true;
  }
  if (after == gt.begin()) return false;
  const StampedPose& b = *after;
  const StampedPose& a = *(after - 1);
  if (!a.valid || !b.valid || b.timestamp - a.timestamp > max_gap_s) return false;
  const double s = (t - a.timestamp) / (b.timestamp - a.timestamp);
  const Eigen::Quaterniond qa(a.T_world_cam.rotation()), qb(b.T_world_cam.rotation());
  T->setIdentity();
  T->linear() = qa.slerp(s, qb).toRotationMatrix();
  T->translation() = (1 - s) * a.T_world_cam.translation() + s * b.T_world_cam.translation();
  return true;
}

Status evaluateNees(const std::vector<StampedPose>& gt, const CovarianceFile& file, const StampedPose& anchor,
                    const NeesOptions& options, NeesResult* out) {
  *out = NeesResult{};
  if (gt.empty()) return Status::Error("ground truth is empty");
  for (std::size_t i = 1; i < gt.size(); ++i) {
    if (gt[i].timestamp < gt[i - 1].timestamp) return Status::Error("ground truth is not sorted by time");
  }
  const double gap = options.max_gt_gap_s;

  Samples relative;
  for (const StampedCovariance& k : file.keyframes) {
    if (!k.valid || !k.has_relative) continue;
    Eigen::Isometry3d G_prev, G_this;
    if (!interpolatePose(gt, k.previous_timestamp, gap, &G_prev) || !interpolatePose(gt, k.timestamp, gap, &G_this)) {
      ++relative.skipped;
      continue;
    }
    relative.add(relativePoseError(G_prev.inverse() * G_this, k.T_previous_this), k.relative_covariance);
  }
  out->keyframe_relative = relative.statistics();

  Samples world, motion;
  Eigen::Isometry3d G_anchor;
  const bool anchored = anchor.valid && interpolatePose(gt, anchor.timestamp, gap, &G_anchor);
  // Ground truth in the estimate's world: T_est(t0) G(t0)^-1 G(t).
  const Eigen::Isometry3d T_est_gt = anchored ? Eigen::Isometry3d(anchor.T_world_cam * G_anchor.inverse())
                                              : Eigen::Isometry3d::Identity();
  const StampedTrackedCovariance* previous = nullptr;
  Eigen::Isometry3d G_previous = Eigen::Isometry3d::Identity();
  for (const StampedTrackedCovariance& f : file.frames) {
    Eigen::Isometry3d G;
    const bool have_truth = f.valid && interpolatePose(gt, f.timestamp, gap, &G);
    if (f.valid && !have_truth) {
      ++world.skipped;
      ++motion.skipped;
    }
    if (have_truth && anchored) {
      const Eigen::Isometry3d G_est_world = T_est_gt * G;
      world.add(logSE3(f.T_world_cam.inverse() * G_est_world), f.covariance);
    }
    if (have_truth && previous != nullptr && f.timestamp - previous->timestamp <= options.max_frame_gap_s) {
      // The previous frame as this frame's map places it when the file has it (what MAVLink's
      // velocity is made from: no map update between the two frames in the motion).
      const bool in_map = f.has_previous && std::abs(f.previous_timestamp - previous->timestamp) < 1e-6;
      const Eigen::Isometry3d T_i = (in_map ? f.T_world_previous : previous->T_world_cam).inverse();
      const Eigen::Isometry3d T_j = f.T_world_cam.inverse();
      const Matrix6d C = relativePoseCovariance(T_i, T_j, previous->covariance_local, f.covariance_local, Matrix6d::Zero());
      motion.add(relativePoseError(G_previous.inverse() * G, T_i * T_j.inverse()), C);
    }
    previous = have_truth ? &f : nullptr;
    G_previous = G;
  }
  if (!anchored) world.skipped = 0;
  out->tracked_world = world.statistics();
  out->frame_motion = motion.statistics();
  return Status::Ok();
}

}  // namespace plumb

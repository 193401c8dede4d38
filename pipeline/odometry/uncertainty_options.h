#pragma once
// Calibration of the covariances plumb publishes (docs/UNCERTAINTY.md): what the estimator's noise
// model does not know, as explicit terms with their justification, measured by NEES against ground
// truth (`plumb eval --nees`, scripts/nees_study.sh). These change what is PUBLISHED (covariance
// files, MAVLink, the loop closer's weights); they do not change any estimate.
#include <string>

#include <Eigen/Core>

namespace plumb {

struct UncertaintyOptions {
  // Scale BA's and pose-only's covariances by their a posteriori variance factor sigma0^2
  // (solver/variance_factor.h): the noise level the residuals show instead of the model's.
  bool use_variance_factor = true;
  // Local BA only: instead of one pooled factor, the points' pixel residuals and their depth
  // (disparity) residuals each get their own a posteriori factor (variance components: two
  // independent sensors whose model errors differ, e.g. a rendering's corners are 3x better than
  // the 1 px model and its depth is as modelled), and line samples keep the model's information:
  // their residuals cannot show their noise (each sample's own 3D point absorbs all but V - 2 of
  // its V residuals, and the samples of one line share the one 2D line of each image), yet pooled
  // they counted as redundancy and pulled everyone's factor down (synth office scenes: 0.16
  // pooled, 0.30 from points alone). docs/UNCERTAINTY.md "Variance components". relative_scale
  // is calibrated WITH this on; with it off (the pooled factor) the calibrated value was 1.8.
  bool variance_components = true;
  // Scale on local BA's relative-pose covariance (keyframe to keyframe) and model-error floor
  // sigmas added to it (independent per keyframe pair).
  // 1.2 / 1.5: Monte Carlo calibration on synthetic scenes (docs/UNCERTAINTY.md): the errors of
  // one landmark's observations are correlated across frames (the same corner of the same texture
  // is detected with the same offset from nearby viewpoints), so the independent-noise information
  // overstates what the observations know even after the variance factor. relative_scale was 1.8
  // with the pooled factor; with variance_components (below) synth:textured seeds 11-30 gave
  // NEES/dof 0.662 at 1.8, so 1.8 * 0.662 = 1.2.
  double relative_scale = 1.2;
  // Floors: off. The model errors measured so far are explained by the terms below; a floor in
  // metres would claim the same absolute error for a slow robot and a fast hand.
  double relative_floor_translation_m = 0.0;
  double relative_floor_rotation_rad = 0.0;
  // Scale on the tracked pose's covariance relative to the map (pose-only optimisation with the
  // landmarks held fixed) and its floor sigmas.
  double tracked_scale = 1.5;
  // Add the landmarks' own position errors to the tracked pose's WORLD covariance (not to the
  // map-relative one the velocity uses: consecutive frames share them). Pose-only optimisation
  // holds the landmarks exact; a landmark from n keyframe measurements is taken to carry 1/n of
  // one measurement's covariance (solver/pose_optimizer.h, Tracker::mapShare), so right after a
  // keyframe, whose landmarks were measured once, the frame's error relative to it is about twice
  // what pose-only says. Scaled like the tracked covariance (variance factor, tracked_scale).
  // On by default since 2026-11-27 (docs/UNCERTAINTY.md "The map error, on by default"): over
  // 150 frames the tracked pose's NEES/dof went from 1.145 to 0.919 on synth:textured (50 seeds),
  // 1.86 -> 1.52 low_texture, 2.53 -> 1.72 office_loop, 1.45 -> 1.24 office_pass (10 seeds each),
  // head250 0.865 -> 0.860. (On an older tree, before the keyframe variance components, it took
  // textured to 0.74, which is why it was off.) Off: the pose-only covariance alone, and the
  // optimiser skips the accumulation (~0.07 M instructions a frame on head250).
  bool tracked_map_error = true;
  double tracked_floor_translation_m = 0.0;
  double tracked_floor_rotation_rad = 0.0;
  // Scale on the pose-only covariance in the frame-to-frame motion (TrackResult::covariance_local,
  // MAVLink's velocity), in place of tracked_scale. tracked_scale stands for errors that persist
  // from frame to frame (the same corner detected with the same offset from nearby viewpoints);
  // two consecutive frames share them and their difference cancels them, as it cancels the map
  // error above and most of the rolling-shutter term (rolling_shutter_frame_share). 1.0: the pose-
  // only information with its variance factor, no correlation factor. Not fitted: with 1.5 the
  // motion NEES/dof was 0.604 on synth:textured and 0.815 on synth:office_loop (10 seeds each,
  // covariances ~1.5x too large once map updates no longer hid it); docs/UNCERTAINTY.md "The
  // motion's own scale".
  double motion_scale = 1.0;
  // Scale on a loop constraint's covariance (the loop verifier's refinement of the query against
  // the candidate's points, both ends' noise propagated; docs/LOOP.md "The loop constraint's
  // covariance"), after its variance factor. The refinement is a pose-only optimisation and the
  // same correlation argument holds, so it takes tracked_scale's value: with 1.0 the loops of
  // synth:loop and synth:office_loop (Kinect-like noise, seeds 1-3) gave NEES/dof 1.43 over 59
  // loops, i.e. the pose-only factor measured again.
  double loop_scale = 1.5;
  // Timing model error: the pose published for a frame is the camera's at the frame's timestamp,
  // but the image is not exactly of that instant (timestamp jitter, the rolling-shutter readout
  // compensated with the previous frame's velocity and a readout time that is itself a guess). A
  // timing error dt moves the pose by twist * dt, so sigma_t^2 twist twist^T is added per frame,
  // sigma_t = timing_sigma_s + timing_sigma_per_readout * the camera's rolling-shutter readout.
  // Off by default: on head250 the frame-to-frame errors are not along the motion (a 5 ms term
  // left their NEES at 30), so timing is not what the rolling-shutter term below describes. Set
  // timing_sigma_s for a camera whose timestamps are known to jitter.
  double timing_sigma_s = 0.0;
  double timing_sigma_per_readout = 0.0;
  // Rolling-shutter model error: the readout is compensated with the previous frame's velocity
  // (docs/ODOMETRY.md); the velocity change within a frame is unknown, and its effect on the pose
  // is that change times the readout. sigma = readout * (these velocity sigmas), isotropic,
  // per frame and per keyframe (zero for a global-shutter camera).
  // 0.15 m/s and 0.15 rad/s (8.6 deg/s): calibrated on the first half of TUM fr1/rpy head250,
  // checked on its second half and fr1/desk (docs/UNCERTAINTY.md); with the 25 ms Kinect readout,
  // 3.75 mm and 0.21 deg per frame.
  double rolling_shutter_velocity_sigma_mps = 0.15;
  double rolling_shutter_rate_sigma_radps = 0.15;
  // Share of those sigmas in one tracked frame's covariance (and so in the velocity's). A keyframe
  // pair spans several frames of motion whose errors add up; consecutive frames share most of
  // theirs (the velocity change persists), which their difference cancels.
  // 0.7: calibrated with the sigmas above (first half of head250's frame-to-frame motion).
  double rolling_shutter_frame_share = 0.7;
  // Relative covariance used for chaining when local BA gave none (the loop closer's default).
  double default_translation_sigma_m = 0.02;
  double default_rotation_sigma_rad = 0.01;
  // Physical bounds on a keyframe covariance local BA publishes (its marginal, whose gauge is the
  // window's fixed keyframes a few keyframes away, and the relative pose to its previous keyframe):
  // a keyframe the tracker placed is never that uncertain against its neighbours (1 m, 29 deg), so
  // a larger one is a numerical failure, not a measurement. Refused (the last BA's value is kept,
  // counted as ba_covariances_refused in --stats). The loop closer's odometry-edge bound is the
  // same (LoopCloserOptions::max_edge_*).
  double max_published_translation_sigma_m = 1.0;
  double max_published_rotation_sigma_rad = 0.5;
  // World covariance of the first keyframe of a later map segment (started at the last known pose
  // after tracking was lost: that pose is a guess; the loop closer's weak segment edge).
  double segment_translation_sigma_m = 1.0;
  double segment_rotation_sigma_rad = 0.5;
};

// Empty when usable; otherwise what is wrong (every number finite and >= 0, scales > 0).
std::string validate(const UncertaintyOptions& options);

Eigen::Matrix<double, 6, 6> diagonalPoseCovariance(double sigma_translation_m, double sigma_rotation_rad);
// sigma0^2 * scale * covariance + floor (sigma0^2 = 1 when use_variance_factor is off).
Eigen::Matrix<double, 6, 6> inflateRelativeCovariance(const UncertaintyOptions& options,
                                                      const Eigen::Matrix<double, 6, 6>& ba_relative,
                                                      double variance_factor);
Eigen::Matrix<double, 6, 6> inflateTrackedCovariance(const UncertaintyOptions& options,
                                                     const Eigen::Matrix<double, 6, 6>& pose_only,
                                                     double variance_factor);
// The same with motion_scale: the frame's share in a frame-to-frame motion (tracked floors kept).
Eigen::Matrix<double, 6, 6> inflateMotionCovariance(const UncertaintyOptions& options,
                                                    const Eigen::Matrix<double, 6, 6>& pose_only,
                                                    double variance_factor);
// sigma_t^2 twist twist^T for a camera with this rolling-shutter readout.
Eigen::Matrix<double, 6, 6> timingCovariance(const UncertaintyOptions& options, double readout_s,
                                             const Eigen::Matrix<double, 6, 1>& twist_per_s);
// readout^2 diag(sigma_v^2 I, sigma_w^2 I) of the rolling-shutter model error.
// share: UncertaintyOptions::rolling_shutter_frame_share for a tracked frame, 1 for a keyframe.
Eigen::Matrix<double, 6, 6> rollingShutterCovariance(const UncertaintyOptions& options, double readout_s,
                                                     double share = 1.0);
inline Eigen::Matrix<double, 6, 6> defaultRelativeCovariance(const UncertaintyOptions& o) {
  return diagonalPoseCovariance(o.default_translation_sigma_m, o.default_rotation_sigma_rad);
}

}  // namespace plumb

// LocalMapper: the bounded-window local bundle adjustment around a new keyframe.
#include <algorithm>

#include "pipeline/odometry/local_mapper.h"

#include "solver/factors.h"
#include "solver/noise_model.h"

namespace plumb {

// Ranks the keyframes sharing landmarks with kf_slot by shared count (newer first on ties) and
// returns the best `count` of them.
void LocalMapper::rankCovisible(int kf_slot, int count, FixedVector<int, kMaxMapKeyframes>* out) const {
  std::array<int, kMaxMapKeyframes> shared;
  map_.covisibility(kf_slot, shared);
  FixedVector<std::pair<int, int>, kMaxMapKeyframes> ranked;  // (-shared, -id) sorts best first
  for (std::size_t i = 0; i < kMaxMapKeyframes; ++i) {
    if (int(i) == kf_slot || shared[i] == 0 || !map_.keyframeAlive(int(i))) continue;
    (void)ranked.push_back({-shared[i], -int(map_.keyframe(int(i)).id)});
  }
  std::sort(ranked.begin(), ranked.end());
  out->clear();
  for (const auto& r : ranked) {
    if (int(out->size()) >= count) break;
    (void)out->push_back(map_.findKeyframeSlot(uint32_t(-r.second)));
  }
}

void LocalMapper::selectWindow(int kf_slot) {
  const LocalMapperOptions& o = options_.mapper;
  auto& window = s_->window;
  rankCovisible(kf_slot, o.ba_optimised_keyframes - 1, &window);
  // The new keyframe goes first.
  (void)window.push_back(kf_slot);
  std::rotate(window.begin(), window.end() - 1, window.end());

  // Landmarks: everything the window observes, up to the BA's capacity (newest keyframe first).
  ++stamp_;
  s_->ba_points.clear();
  s_->ba_lines.clear();
  int landmarks = 0;
  for (int slot : window) {
    const Keyframe& kf = map_.keyframe(slot);
    for (const auto& obs : kf.points) {
      if (s_->point_stamp[obs.point_slot] == stamp_ || landmarks >= o.max_ba_landmarks) continue;
      s_->point_stamp[obs.point_slot] = stamp_;
      (void)s_->ba_points.push_back(obs.point_slot);
      ++landmarks;
    }
    for (const auto& obs : kf.lines) {
      const MapLine& l = map_.line(int(obs.line_slot));
      if (s_->line_stamp[obs.line_slot] == stamp_ || landmarks + l.num_samples > o.max_ba_landmarks) continue;
      s_->line_stamp[obs.line_slot] = stamp_;
      (void)s_->ba_lines.push_back(obs.line_slot);
      landmarks += l.num_samples;
    }
  }

  // Fixed keyframes: outside the window, observing the most of those landmarks.
  std::array<int, kMaxMapKeyframes> seen{};
  KeyframeMask window_mask = 0;
  for (int slot : window) window_mask |= KeyframeMask(1) << slot;
  auto count_observers = [&seen, window_mask](KeyframeMask mask) {
    mask &= ~window_mask;
    while (mask) {
      ++seen[__builtin_ctz(mask)];
      mask &= mask - 1;
    }
  };
  for (uint32_t p : s_->ba_points) count_observers(map_.point(int(p)).observers.mask);
  for (uint32_t l : s_->ba_lines) count_observers(map_.line(int(l)).observers.mask);
  FixedVector<std::pair<int, int>, kMaxMapKeyframes> ranked;
  for (std::size_t i = 0; i < kMaxMapKeyframes; ++i) {
    if (seen[i] > 0) (void)ranked.push_back({-seen[i], -int(map_.keyframe(int(i)).id)});
  }
  std::sort(ranked.begin(), ranked.end());
  s_->fixed.clear();
  for (const auto& r : ranked) {
    if (int(s_->fixed.size()) >= o.ba_fixed_keyframes) break;
    (void)s_->fixed.push_back(map_.findKeyframeSlot(uint32_t(-r.second)));
  }
}

// A landmark observed by a single keyframe of the BA (typically the points and lines the new
// keyframe just created) has as many unknowns as its observation has residuals or more (3 for a
// stereo point, 2 for a mono point, 1 for a line sample), so at the optimum its residual is zero
// and it contributes exactly nothing to the poses: eliminating it gives W H_ll^-1 W^T = the
// pose block it added (the Schur complement cancels), for the solution and for the covariance
// alike. What BA does with it is carry it along with its keyframe. So it is left out of the
// problem (about 45% of the landmarks and 20% of the observations of a window on fr1/rpy) and
// moved rigidly with its keyframe's correction afterwards, which is that optimum exactly; one
// seen only by a fixed keyframe does not move. The landmark budget (max_ba_landmarks) still
// counts them, so the BA keeps the landmarks it had.
void LocalMapper::excludeSingleViewLandmarks() {
  KeyframeMask window_mask = 0, ba_mask = 0;
  for (int slot : s_->window) window_mask |= KeyframeMask(1) << slot;
  ba_mask = window_mask;
  for (int slot : s_->fixed) ba_mask |= KeyframeMask(1) << slot;
  auto single_view = [ba_mask](KeyframeMask observers) {
    const KeyframeMask seen = observers & ba_mask;
    return (seen & (seen - 1)) == 0;  // at most one bit
  };
  s_->single_view_points.clear();
  std::size_t kept = 0;
  for (uint32_t p : s_->ba_points) {
    const KeyframeMask observers = map_.point(int(p)).observers.mask;
    if (!single_view(observers)) {
      s_->ba_points[kept++] = p;
      continue;
    }
    s_->point_stamp[p] = 0;  // no BA observation (stamps start at 1)
    if (observers & window_mask) (void)s_->single_view_points.push_back(p);
  }
  s_->ba_points.resize(kept);
  s_->single_view_lines.clear();
  kept = 0;
  for (uint32_t l : s_->ba_lines) {
    const KeyframeMask observers = map_.line(int(l)).observers.mask;
    if (!single_view(observers)) {
      s_->ba_lines[kept++] = l;
      continue;
    }
    s_->line_stamp[l] = 0;
    if (observers & window_mask) (void)s_->single_view_lines.push_back(l);
  }
  s_->ba_lines.resize(kept);
}

// After the window's poses were written back (ba_correction holds each window keyframe's
// T_world_cam new * old^-1): the single-view landmarks follow their keyframe.
void LocalMapper::moveSingleViewLandmarks() {
  KeyframeMask window_mask = 0;
  for (int slot : s_->window) window_mask |= KeyframeMask(1) << slot;
  auto correction_of = [&](KeyframeMask observers) -> const Eigen::Isometry3d& {
    return s_->ba_correction[std::size_t(__builtin_ctz(observers & window_mask))];
  };
  for (uint32_t p : s_->single_view_points) {
    MapPoint& point = map_.point(int(p));
    point.P_world = correction_of(point.observers.mask) * point.P_world;
  }
  for (uint32_t l : s_->single_view_lines) {
    MapLine& line = map_.line(int(l));
    const Eigen::Isometry3d& correction = correction_of(line.observers.mask);
    for (int s = 0; s < line.num_samples; ++s) line.samples_world[s] = correction * line.samples_world[s];
    line.start_world = correction * line.start_world;
    line.end_world = correction * line.end_world;
  }
}

// A line sample is a 3D point measured only by its distance to the 2D line in each view, so its
// depth is unobserved until views far enough apart triangulate it, and never when its line runs
// along the motion. Its first keyframe measured that depth (the sampler back-projected it), so it
// enters the BA like a keypoint's depth in that keyframe, with the noise model's sigma scaled
// for object edges; its pixel only along the line (noise_model.h lineSampleAnchorInformation).
void LocalMapper::addLineSampleAnchors() {
  const CameraIntrinsics& K = intrinsics_;
  for (uint32_t l : s_->ba_lines) {
    const MapLine& line = map_.line(int(l));
    const int kf_slot = map_.findKeyframeSlot(line.first_keyframe_id);
    if (kf_slot < 0 || !line.observers.has(kf_slot)) continue;
    const int kf_index = s_->ba_keyframe_index[kf_slot];
    if (kf_index < 0) continue;  // the first keyframe is outside the BA
    const KeyframeLineObservation& obs = map_.keyframe(kf_slot).lines[line.observers.obs_index[kf_slot]];
    const Eigen::Vector2d normal = obs.l.head<2>().normalized();
    const Eigen::Vector2d along(-normal.y(), normal.x());
    const int first = s_->line_ba_first_index[l];
    for (int s = 0; s < line.num_samples; ++s) {
      const Eigen::Vector3d P = line.samples_first_cam[std::size_t(s)].cast<double>();
      const Eigen::Matrix3d information = lineSampleAnchorInformation(
          options_.extractor.noise, K, obs.octave, P.z(), along, options_.mapper.line_sample_depth_sigma_scale);
      if (!(information(2, 2) > 0.0)) continue;  // no depth (below the noise model's minimum)
      Eigen::Vector3d uvr;  // where the stereo factor predicts it: its residual against zero
      stereoResidualAt(K, P, Eigen::Vector3d::Zero(), &uvr, nullptr);
      if (ba_.addStereoPointObservation(kf_index, first + s, uvr, information) < 0) return;  // full
    }
  }
}

void LocalMapper::runLocalBa(int kf_slot, InsertResult* result) {
  selectWindow(kf_slot);
  auto& window = s_->window;
  auto& fixed = s_->fixed;
  // Gauge: with no keyframe outside the window, the oldest window keyframe is held fixed
  // (ORB-SLAM fixes the map's first keyframe). A lone keyframe has nothing to adjust.
  if (fixed.empty()) {
    if (window.size() < 2) return;
    auto oldest = std::min_element(window.begin(), window.end(), [this](int a, int b) {
      return map_.keyframe(a).id < map_.keyframe(b).id;
    });
    (void)fixed.push_back(*oldest);
    window.resize(std::size_t(std::remove(window.begin(), window.end(), *oldest) - window.begin()));
  }

  excludeSingleViewLandmarks();

  ba_.clear();
  s_->ba_keyframe_index.fill(-1);
  for (int slot : window) s_->ba_keyframe_index[slot] = ba_.addKeyframe(map_.keyframe(slot).T_world_cam.inverse(), false);
  for (int slot : fixed) s_->ba_keyframe_index[slot] = ba_.addKeyframe(map_.keyframe(slot).T_world_cam.inverse(), true);

  for (uint32_t p : s_->ba_points) s_->point_ba_index[p] = ba_.addLandmark(map_.point(int(p)).P_world);
  for (uint32_t l : s_->ba_lines) {
    const MapLine& line = map_.line(int(l));
    s_->line_ba_first_index[l] = ba_.addLandmark(line.samples_world[0]);
    for (int s = 1; s < line.num_samples; ++s) (void)ba_.addLandmark(line.samples_world[s]);
  }

  // Observations of the BA landmarks by every BA keyframe.
  int num_obs = 0;
  const int max_obs = int(ba_observations_.size());
  auto add_keyframe_observations = [&](int slot) {
    const int kf_index = s_->ba_keyframe_index[slot];
    const Keyframe& kf = map_.keyframe(slot);
    for (const auto& obs : kf.points) {
      if (s_->point_stamp[obs.point_slot] != stamp_ || num_obs >= max_obs) continue;
      const int landmark = s_->point_ba_index[obs.point_slot];
      const int o = obs.has_depth
                        ? ba_.addStereoPointObservation(kf_index, landmark, obs.uvr, obs.info)
                        : ba_.addMonoPointObservation(kf_index, landmark, obs.uvr.head<2>(),
                                                      obs.info.topLeftCorner<2, 2>());
      if (o < 0) continue;
      ba_observations_[std::size_t(o)] = BaObservation{uint8_t(slot), false, obs.point_slot};
      num_obs = o + 1;
    }
    if (!options_.tracker.use_lines) return;
    for (const auto& obs : kf.lines) {
      if (s_->line_stamp[obs.line_slot] != stamp_) continue;
      const MapLine& line = map_.line(int(obs.line_slot));
      const int first = s_->line_ba_first_index[obs.line_slot];
      for (int s = 0; s < line.num_samples && num_obs < max_obs; ++s) {
        const int o = ba_.addLineObservation(kf_index, first + s, obs.l, obs.info);
        if (o < 0) break;
        ba_observations_[std::size_t(o)] = BaObservation{uint8_t(slot), true, obs.line_slot};
        num_obs = o + 1;
      }
    }
  };
  for (int slot : window) add_keyframe_observations(slot);
  for (int slot : fixed) add_keyframe_observations(slot);
  // After the others: the outlier bookkeeping below walks observations [0, num_obs) only.
  if (options_.tracker.use_lines && options_.mapper.anchor_line_sample_depth) addLineSampleAnchors();

  const LocalBaSummary summary = ba_.solve(ba_options_);
  ++stats_.ba_runs;
  stats_.ba_outlier_flags += uint64_t(summary.num_outliers);
  result->ba_initial_cost = summary.initial_cost;
  result->ba_final_cost = summary.final_cost;
  if (!summary.ok()) {
    writeUncertainty(kf_slot, false, 1.0);
    return;
  }

  // Write back poses, landmarks, covariances.
  // Before computeCovariance, which re-evaluates chi2. With variance components the factors are in
  // the information (pixel and depth parts of the points each by their own, line samples as
  // modelled) and the pooled factor is 1 (docs/UNCERTAINTY.md).
  const UncertaintyOptions& u = options_.uncertainty;
  double variance_factor = 1.0;
  InformationScales scales;
  if (u.use_variance_factor && u.variance_components) {
    const PointVarianceComponents components = ba_.varianceComponents(ba_options_);
    scales.pixel = 1.0 / components.pixel;
    scales.depth = 1.0 / components.depth;
  } else if (u.use_variance_factor) {
    variance_factor = ba_.varianceFactor(ba_options_);
  }
  const bool have_covariance = ba_.computeCovariance(ba_options_, scales);
  if (!have_covariance) ++stats_.ba_covariances_refused;  // singular: the keyframes keep the last BA's
  for (int slot : window) {
    Keyframe& kf = map_.keyframe(slot);
    const int index = s_->ba_keyframe_index[slot];
    const Eigen::Isometry3d T_world_cam = ba_.pose(index).inverse();
    s_->ba_correction[std::size_t(slot)] = T_world_cam * kf.T_world_cam.inverse();
    kf.T_world_cam = T_world_cam;
    if (have_covariance) {
      // Calibrated like the relative covariances (docs/UNCERTAINTY.md); its gauge is this BA's
      // fixed keyframes.
      const Matrix6d covariance = variance_factor * u.relative_scale * ba_.covariance(index);
      if (publishable(covariance)) {
        kf.covariance = covariance;
        kf.covariance_valid = true;
      }
    }
  }
  moveSingleViewLandmarks();
  writeUncertainty(kf_slot, have_covariance, variance_factor);
  for (uint32_t p : s_->ba_points) map_.point(int(p)).P_world = ba_.landmark(s_->point_ba_index[p]);
  for (uint32_t l : s_->ba_lines) {
    MapLine& line = map_.line(int(l));
    const int first = s_->line_ba_first_index[l];
    Eigen::Vector3d shift = Eigen::Vector3d::Zero();
    for (int s = 0; s < line.num_samples; ++s) {
      const Eigen::Vector3d updated = ba_.landmark(first + s);
      shift += updated - line.samples_world[s];
      line.samples_world[s] = updated;
    }
    shift /= double(line.num_samples);
    line.start_world += shift;  // the segment's extent moves with its samples
    line.end_world += shift;
  }

  // Outlier observations leave the map when enabled (off by default: counted in
  // ba_outlier_flags above, not acted on). A line observation goes when most of its samples fail.
  result->ba_outliers = 0;
  if (!options_.mapper.remove_ba_outliers) return;
  int outliers = 0;
  int o = 0;
  while (o < num_obs) {
    const BaObservation& obs = ba_observations_[std::size_t(o)];
    if (!obs.is_line) {
      if (ba_.isOutlier(o)) {
        map_.removePointObservation(obs.kf_slot, int(obs.slot));
        if (map_.point(int(obs.slot)).observers.mask == 0) map_.removePoint(int(obs.slot));
        ++outliers;
      }
      ++o;
      continue;
    }
    int total = 0, bad = 0;
    const int start = o;
    for (; o < num_obs && ba_observations_[std::size_t(o)].is_line &&
           ba_observations_[std::size_t(o)].slot == obs.slot && ba_observations_[std::size_t(o)].kf_slot == obs.kf_slot &&
           o - start < int(kMaxLineSamples);
         ++o) {
      ++total;
      bad += ba_.isOutlier(o) ? 1 : 0;
    }
    MapLine& line = map_.line(int(obs.slot));
    line.sample_evaluations += uint32_t(total);
    line.sample_outliers += uint32_t(bad);
    if (2 * bad > total) {
      map_.removeLineObservation(obs.kf_slot, int(obs.slot));
      if (line.observers.mask == 0) map_.removeLine(int(obs.slot));
      ++outliers;
    }
  }
  result->ba_outliers = outliers;
  stats_.ba_outlier_observations += uint64_t(outliers);
}

}  // namespace plumb

#pragma once
// Seeded synthetic local-BA windows with exact ground truth, shared by the solver tests and
// bench/solver: keyframes on an arc looking at a box of points and 3D line segments, RGB-D point
// observations [u, v, u_r] with the paper's noise model, monocular [u, v] ones, and line-guidance
// samples observed through the (noisy) projected line. Header-only so the benchmark can use it.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "solver/camera_intrinsics.h"
#include "solver/factors.h"
#include "solver/local_ba.h"
#include "solver/noise_model.h"
#include "solver/se3.h"

namespace plumb::testing {

struct SyntheticWindowConfig {
  unsigned seed = 1;
  int num_keyframes = 6;
  int num_fixed = 2;  // the first num_fixed keyframes are fixed
  int num_points = 200;  // point landmarks seen by >= 2 keyframes
  int num_lines = 20;    // 3D segments seen by >= 2 keyframes, samples_per_line landmarks each
  int samples_per_line = 5;
  int views_per_landmark = 8;  // capped by the number of keyframes that see the landmark
  double mono_fraction = 0.2;  // point observations without depth
  double pixel_noise = 0.5;    // [px] std of u, v (and of the line endpoints)
  bool depth_noise = true;     // depth noise from the noise model
  double outlier_fraction = 0.0;
  double pose_perturbation_rad = 0.01;  // initial error of free keyframes
  double pose_perturbation_m = 0.02;
  double landmark_perturbation_m = 0.03;
};

struct SyntheticObservation {
  int keyframe = 0;
  int landmark = 0;
  ObservationKind kind = ObservationKind::kStereoPoint;
  Eigen::Vector3d z = Eigen::Vector3d::Zero();  // [u,v,u_r] | [u,v,0] | line
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  bool is_outlier = false;
};

struct SyntheticWindow {
  CameraIntrinsics camera{525.0, 525.0, 319.5, 239.5, 525.0 * 0.08};
  std::vector<Eigen::Isometry3d> T_cam_world_true;
  std::vector<Eigen::Isometry3d> T_cam_world_initial;
  std::vector<bool> fixed;
  std::vector<Eigen::Vector3d> P_world_true;
  std::vector<Eigen::Vector3d> P_world_initial;
  std::vector<bool> is_line_sample;
  std::vector<SyntheticObservation> observations;
};

inline Eigen::Isometry3d lookAtCamFromWorld(const Eigen::Vector3d& centre, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - centre).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d(0.0, 1.0, 0.0).cross(z).normalized();  // image y points down
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  T_world_cam.linear().col(0) = x;
  T_world_cam.linear().col(1) = y;
  T_world_cam.linear().col(2) = z;
  T_world_cam.translation() = centre;
  return T_world_cam.inverse();
}

inline bool inImage(const Eigen::Vector2d& uv) {
  return uv.x() > 5.0 && uv.x() < 635.0 && uv.y() > 5.0 && uv.y() < 475.0;
}

inline SyntheticWindow makeSyntheticWindow(const SyntheticWindowConfig& config) {
  SyntheticWindow w;
  std::mt19937 rng(config.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  auto randomVector = [&] { return Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)); };
  const NoiseModelOptions noise;

  for (int i = 0; i < config.num_keyframes; ++i) {
    const double angle = 2.0 * M_PI * i / std::max(config.num_keyframes, 1);
    const Eigen::Vector3d centre(0.6 * std::cos(angle), 0.3 * std::sin(angle), 0.1 * gauss(rng));
    const Eigen::Vector3d target = Eigen::Vector3d(0.0, 0.0, 3.5) + 0.2 * randomVector();
    const Eigen::Isometry3d T = lookAtCamFromWorld(centre, target);
    const bool fixed = i < config.num_fixed;
    w.T_cam_world_true.push_back(T);
    w.fixed.push_back(fixed);
    Vector6d delta;
    delta << config.pose_perturbation_m * randomVector(), config.pose_perturbation_rad * randomVector();
    w.T_cam_world_initial.push_back(fixed ? T : applyLeftIncrement(delta, T));
  }

  auto randomScenePoint = [&] {
    return Eigen::Vector3d(-2.0 + 4.0 * uniform(rng), -1.5 + 3.0 * uniform(rng), 2.5 + 2.5 * uniform(rng));
  };
  // Keyframes that see P, shuffled, at most views_per_landmark.
  auto pickViews = [&](const Eigen::Vector3d& P, std::vector<int>* views) {
    views->clear();
    for (int i = 0; i < config.num_keyframes; ++i) {
      const Eigen::Vector3d P_cam = w.T_cam_world_true[i] * P;
      if (P_cam.z() > 0.5 && inImage(projectToPixel(w.camera, P_cam))) views->push_back(i);
    }
    std::shuffle(views->begin(), views->end(), rng);
    if (static_cast<int>(views->size()) > config.views_per_landmark) views->resize(config.views_per_landmark);
  };
  auto addLandmark = [&](const Eigen::Vector3d& P, bool line_sample) {
    w.P_world_true.push_back(P);
    w.P_world_initial.push_back(P + config.landmark_perturbation_m * randomVector());
    w.is_line_sample.push_back(line_sample);
    return static_cast<int>(w.P_world_true.size()) - 1;
  };
  const double sp = config.pixel_noise;
  std::vector<int> views;

  // Draw until num_points points are seen by at least two keyframes (bounded number of draws).
  int num_points = 0;
  for (int draw = 0; num_points < config.num_points && draw < 50 * config.num_points; ++draw) {
    const Eigen::Vector3d P = randomScenePoint();
    pickViews(P, &views);
    if (views.size() < 2) continue;
    ++num_points;
    const int lm = addLandmark(P, false);
    for (int i : views) {
      SyntheticObservation obs;
      obs.keyframe = i;
      obs.landmark = lm;
      const Eigen::Vector3d P_cam = w.T_cam_world_true[i] * P;
      const Eigen::Vector2d uv = projectToPixel(w.camera, P_cam) + Eigen::Vector2d(sp * gauss(rng), sp * gauss(rng));
      obs.is_outlier = uniform(rng) < config.outlier_fraction;
      const Eigen::Vector2d uv_meas =
          obs.is_outlier ? Eigen::Vector2d(640.0 * uniform(rng), 480.0 * uniform(rng)) : uv;
      if (uniform(rng) < config.mono_fraction) {
        obs.kind = ObservationKind::kMonoPoint;
        obs.z << uv_meas, 0.0;
        obs.information.topLeftCorner<2, 2>() = monoPointInformation(noise, 0);
      } else {
        obs.kind = ObservationKind::kStereoPoint;
        const double depth = P_cam.z() + (config.depth_noise ? depthSigma(noise, P_cam.z()) * gauss(rng) : 0.0);
        obs.z << uv_meas, uv_meas.x() - w.camera.bf / depth;
        obs.information = stereoPointInformation(noise, w.camera, 0, depth);
      }
      w.observations.push_back(obs);
    }
  }

  int num_lines = 0;
  for (int draw = 0; num_lines < config.num_lines && draw < 50 * config.num_lines; ++draw) {
    const Eigen::Vector3d A = randomScenePoint();
    const Eigen::Vector3d B = A + (0.5 + uniform(rng)) * randomVector().normalized();
    const Eigen::Vector3d M = 0.5 * (A + B);
    pickViews(M, &views);
    // Both endpoints must be in front of every view, else the image line is meaningless.
    views.erase(std::remove_if(views.begin(), views.end(),
                               [&](int i) {
                                 return (w.T_cam_world_true[i] * A).z() < 0.5 || (w.T_cam_world_true[i] * B).z() < 0.5;
                               }),
                views.end());
    if (views.size() < 2) continue;
    ++num_lines;
    const int first = static_cast<int>(w.P_world_true.size());
    for (int s = 0; s < config.samples_per_line; ++s) {
      const double t = (s + 0.5) / config.samples_per_line;
      addLandmark(A + t * (B - A), true);
    }
    for (int i : views) {
      const Eigen::Vector2d a = projectToPixel(w.camera, w.T_cam_world_true[i] * A) +
                                Eigen::Vector2d(sp * gauss(rng), sp * gauss(rng));
      const Eigen::Vector2d b = projectToPixel(w.camera, w.T_cam_world_true[i] * B) +
                                Eigen::Vector2d(sp * gauss(rng), sp * gauss(rng));
      Eigen::Vector3d line = Eigen::Vector3d::Zero();
      normalizeLine(Eigen::Vector3d(a.x(), a.y(), 1.0).cross(Eigen::Vector3d(b.x(), b.y(), 1.0)), &line);
      for (int s = 0; s < config.samples_per_line; ++s) {
        SyntheticObservation obs;
        obs.keyframe = i;
        obs.landmark = first + s;
        obs.kind = ObservationKind::kLineSample;
        obs.z = line;
        obs.is_outlier = uniform(rng) < config.outlier_fraction;
        if (obs.is_outlier) obs.z(2) += 30.0 * (uniform(rng) < 0.5 ? -1.0 : 1.0);  // shifted 30 px
        obs.information(0, 0) = lineSampleInformation(noise, 0);
        w.observations.push_back(obs);
      }
    }
  }
  return w;
}

// Loads the window into a solver sized for it. initial = false loads the ground truth.
inline void loadWindow(const SyntheticWindow& w, bool initial, LocalBundleAdjuster* ba) {
  ba->reserve(static_cast<int>(w.T_cam_world_true.size()), static_cast<int>(w.P_world_true.size()),
              static_cast<int>(w.observations.size()));
  ba->setCamera(w.camera);
  for (size_t i = 0; i < w.T_cam_world_true.size(); ++i) {
    ba->addKeyframe(initial ? w.T_cam_world_initial[i] : w.T_cam_world_true[i], w.fixed[i]);
  }
  for (size_t j = 0; j < w.P_world_true.size(); ++j) {
    ba->addLandmark(initial ? w.P_world_initial[j] : w.P_world_true[j]);
  }
  for (const SyntheticObservation& obs : w.observations) {
    switch (obs.kind) {
      case ObservationKind::kStereoPoint:
        ba->addStereoPointObservation(obs.keyframe, obs.landmark, obs.z, obs.information);
        break;
      case ObservationKind::kMonoPoint:
        ba->addMonoPointObservation(obs.keyframe, obs.landmark, obs.z.head<2>(),
                                    obs.information.topLeftCorner<2, 2>());
        break;
      case ObservationKind::kLineSample:
        ba->addLineObservation(obs.keyframe, obs.landmark, obs.z, obs.information(0, 0));
        break;
    }
  }
}

// Rotation angle [rad] and translation distance [m] between two camera poses.
inline double rotationError(const Eigen::Isometry3d& A, const Eigen::Isometry3d& B) {
  return logSO3(A.linear() * B.linear().transpose()).norm();
}
inline double centreError(const Eigen::Isometry3d& A, const Eigen::Isometry3d& B) {
  return (A.inverse().translation() - B.inverse().translation()).norm();
}

}  // namespace plumb::testing

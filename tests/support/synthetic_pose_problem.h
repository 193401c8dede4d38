#pragma once
// A seeded single-frame problem for pose-only optimisation (shared by tests and bench/solver):
// map points (20% without depth) and line-guidance samples with known world positions, noisy
// observations from the paper's noise model, and a chosen fraction of gross outliers.
#include <random>
#include <vector>

#include "solver/noise_model.h"
#include "solver/pose_optimizer.h"
#include "tests/support/synthetic_window.h"

namespace plumb::testing {

struct PoseProblem {
  CameraIntrinsics camera{525.0, 525.0, 319.5, 239.5, 42.0};
  Eigen::Isometry3d T_cam_world_true = Eigen::Isometry3d::Identity();
  std::vector<PosePointObservation> points;
  std::vector<bool> point_is_outlier;
  std::vector<PoseLineObservation> lines;
  std::vector<bool> line_is_outlier;
};

// One frame seeing num_points map points (20% without depth) and num_lines x 5 line samples.
inline PoseProblem makePoseProblem(unsigned seed, int num_points, int num_lines, double outlier_fraction) {
  PoseProblem p;
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const NoiseModelOptions noise;
  p.T_cam_world_true = lookAtCamFromWorld(Eigen::Vector3d(0.2, -0.1, 0.0), Eigen::Vector3d(0.1, 0.2, 3.5));
  const Eigen::Isometry3d T_world_cam = p.T_cam_world_true.inverse();
  auto randomVisiblePoint = [&] {
    const double depth = 1.0 + 4.0 * uniform(rng);
    const Eigen::Vector3d ray((600.0 * uniform(rng) + 20.0 - p.camera.cx) / p.camera.fx,
                              (440.0 * uniform(rng) + 20.0 - p.camera.cy) / p.camera.fy, 1.0);
    return Eigen::Vector3d(T_world_cam * (depth * ray));
  };
  for (int n = 0; n < num_points; ++n) {
    PosePointObservation obs;
    obs.P_world = randomVisiblePoint();
    const Eigen::Vector3d P_cam = p.T_cam_world_true * obs.P_world;
    Eigen::Vector2d uv = projectToPixel(p.camera, P_cam) + 0.5 * Eigen::Vector2d(gauss(rng), gauss(rng));
    const bool outlier = uniform(rng) < outlier_fraction;
    if (outlier) uv += Eigen::Vector2d(20.0 + 60.0 * uniform(rng), -20.0 - 60.0 * uniform(rng));
    obs.has_depth = uniform(rng) > 0.2;
    const double depth = P_cam.z() + depthSigma(noise, P_cam.z()) * gauss(rng);
    obs.z << uv, uv.x() - p.camera.bf / depth;
    if (obs.has_depth) {
      obs.information = stereoPointInformation(noise, p.camera, 0, depth);
    } else {
      obs.information.setZero();
      obs.information.topLeftCorner<2, 2>() = monoPointInformation(noise, 0);
    }
    p.points.push_back(obs);
    p.point_is_outlier.push_back(outlier);
  }
  for (int n = 0; n < num_lines; ++n) {
    const Eigen::Vector3d A = randomVisiblePoint();
    const Eigen::Vector3d B = randomVisiblePoint();
    const Eigen::Vector2d a = projectToPixel(p.camera, p.T_cam_world_true * A) + 0.5 * Eigen::Vector2d(gauss(rng), gauss(rng));
    const Eigen::Vector2d b = projectToPixel(p.camera, p.T_cam_world_true * B) + 0.5 * Eigen::Vector2d(gauss(rng), gauss(rng));
    Eigen::Vector3d line = Eigen::Vector3d::Zero();
    normalizeLine(Eigen::Vector3d(a.x(), a.y(), 1.0).cross(Eigen::Vector3d(b.x(), b.y(), 1.0)), &line);
    const bool outlier = uniform(rng) < outlier_fraction;
    if (outlier) line.z() += 25.0;
    for (int s = 0; s < 5; ++s) {
      PoseLineObservation obs;
      obs.P_world = A + (s + 0.5) / 5.0 * (B - A);
      obs.line = line;
      obs.information = lineSampleInformation(noise, 0);
      p.lines.push_back(obs);
      p.line_is_outlier.push_back(outlier);
    }
  }
  return p;
}

}  // namespace plumb::testing

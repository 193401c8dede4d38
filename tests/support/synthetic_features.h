#pragma once
// Hand-built value messages for the odometry component tests: a seeded 3D scene of points (each
// with its own random 256-bit descriptor and orientation) and line segments, observed from a
// known camera pose into a FrameFeatures exactly as the front end would fill it (undistorted
// pixels, depth, back-projected P_cam, u_r, the noise model's [u, v, u_r] information, line
// coefficients and 3D line-guidance samples). No images, no extractor: the ground truth is the
// scene itself, so the tests judge the tracker / mapper / relocalizer against it directly.
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "pipeline/frontend/frame_features.h"
#include "pipeline/odometry/keyframe_request.h"
#include "sensor/camera.h"
#include "solver/camera_intrinsics.h"
#include "solver/noise_model.h"

namespace plumb::test {

// Kinect-like pinhole camera without distortion (raw pixel == undistorted pixel).
inline PinholeCamera syntheticCamera() {
  PinholeCamera c;
  c.fx = 525;
  c.fy = 525;
  c.cx = 319.5;
  c.cy = 239.5;
  c.width = 640;
  c.height = 480;
  c.baseline_m = 0.08;
  return c;
}

inline CameraIntrinsics intrinsicsOf(const PinholeCamera& c) {
  return CameraIntrinsics{c.fx, c.fy, c.cx, c.cy, c.fx * c.baseline_m};
}

// T_world_cam from an axis-angle rotation (degrees) and a translation.
inline Eigen::Isometry3d pose(double angle_deg, const Eigen::Vector3d& axis, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(angle_deg * M_PI / 180.0, axis.normalized()).toRotationMatrix();
  T.translation() = t;
  return T;
}

inline double translationError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.translation() - b.translation()).norm();
}
inline double rotationErrorDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180.0 / M_PI;
}

inline Descriptor256 randomDescriptor(std::mt19937_64& rng) {
  Descriptor256 d;
  for (auto& w : d.words) w = rng();
  return d;
}

struct ScenePoint {
  Eigen::Vector3d P_world;
  Descriptor256 descriptor;
  float angle_deg = 0;
  float response = 0;
};

struct SceneLine {
  Eigen::Vector3d A_world, B_world;  // segment endpoints
  Descriptor256 descriptor;
};

struct Scene {
  std::vector<ScenePoint> points;
  std::vector<SceneLine> lines;
};

// Points spread over the image of a camera at T_world_cam0, at depths [min_depth, max_depth];
// lines are 0.3-0.5 m segments in random directions at 1.5-3 m, kept short enough to stay in view
// of nearby poses.
inline Scene makeScene(uint64_t seed, int num_points, int num_lines, const Eigen::Isometry3d& T_world_cam0,
                       double min_depth = 1.0, double max_depth = 4.0) {
  const PinholeCamera camera = syntheticCamera();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(60, 580), v(60, 420), depth(min_depth, max_depth), unit(-1, 1);
  std::uniform_real_distribution<double> angle(0, 359), response(10, 100);
  Scene scene;
  for (int i = 0; i < num_points; ++i) {
    ScenePoint p;
    p.P_world = T_world_cam0 * camera.unproject(u(rng), v(rng), depth(rng));
    p.descriptor = randomDescriptor(rng);
    p.angle_deg = float(angle(rng));
    p.response = float(response(rng));
    scene.points.push_back(p);
  }
  std::uniform_real_distribution<double> line_u(160, 480), line_v(130, 350), line_depth(1.5, 3.0), length(0.3, 0.5);
  for (int i = 0; i < num_lines; ++i) {
    const Eigen::Vector3d centre = camera.unproject(line_u(rng), line_v(rng), line_depth(rng));
    Eigen::Vector3d dir(unit(rng), unit(rng), 0.3 * unit(rng));  // mostly across the view
    dir.normalize();
    const double half = 0.5 * length(rng);
    SceneLine l;
    l.A_world = T_world_cam0 * Eigen::Vector3d(centre - half * dir);
    l.B_world = T_world_cam0 * Eigen::Vector3d(centre + half * dir);
    l.descriptor = randomDescriptor(rng);
    scene.lines.push_back(l);
  }
  return scene;
}

// A FrameFeatures plus which scene feature each keypoint / line came from.
struct View {
  std::unique_ptr<FrameFeatures> features = std::make_unique<FrameFeatures>();
  std::vector<int> keypoint_point;  // keypoint index -> scene point index
  std::vector<int> line_segment;    // line index -> scene line index
};

inline void addKeypoint(const PinholeCamera& camera, const Eigen::Vector3d& P_cam, const Descriptor256& descriptor,
                        float angle_deg, float response, bool with_depth, FrameFeatures* f) {
  const NoiseModelOptions noise;
  KeypointObservation* kp = f->keypoints.emplace_back();
  kp->px_undist = camera.project(P_cam).cast<float>();
  kp->px = kp->px_undist;
  kp->angle_deg = angle_deg;
  kp->response = response;
  kp->octave = 0;
  if (with_depth) {
    kp->depth_m = float(P_cam.z());
    kp->u_right = float(kp->px_undist.x() - camera.fx * camera.baseline_m / P_cam.z());
    kp->P_cam = P_cam.cast<float>();
    kp->info_uvr = stereoPointInformation(noise, intrinsicsOf(camera), 0, P_cam.z()).cast<float>();
  }
  (void)f->keypoint_descriptors.push_back(descriptor);
}

// Observes `scene` from T_world_cam: every point in front of the camera and inside the image
// becomes a keypoint (with depth unless the point's index is in the 2D-only stride), every line
// whose endpoints are both in view becomes a line with `samples` 3D guidance samples.
inline View observe(const Scene& scene, const Eigen::Isometry3d& T_world_cam, int mono_every = 0, int samples = 5) {
  const PinholeCamera camera = syntheticCamera();
  const Eigen::Isometry3d T_cam_world = T_world_cam.inverse();
  View view;
  FrameFeatures& f = *view.features;
  for (std::size_t i = 0; i < scene.points.size(); ++i) {
    const ScenePoint& p = scene.points[i];
    const Eigen::Vector3d P_cam = T_cam_world * p.P_world;
    if (P_cam.z() < 0.3) continue;
    const Eigen::Vector2d px = camera.project(P_cam);
    if (!camera.inImage(px.x(), px.y(), 10)) continue;
    if (f.keypoints.full()) break;
    const bool with_depth = mono_every == 0 || i % std::size_t(mono_every) != 0;
    addKeypoint(camera, P_cam, p.descriptor, p.angle_deg, p.response, with_depth, &f);
    view.keypoint_point.push_back(int(i));
  }
  for (std::size_t i = 0; i < scene.lines.size(); ++i) {
    const SceneLine& sl = scene.lines[i];
    const Eigen::Vector3d A = T_cam_world * sl.A_world, B = T_cam_world * sl.B_world;
    if (A.z() < 0.3 || B.z() < 0.3) continue;
    const Eigen::Vector2d a = camera.project(A), b = camera.project(B);
    if (!camera.inImage(a.x(), a.y(), 10) || !camera.inImage(b.x(), b.y(), 10)) continue;
    if (f.lines.full()) break;
    LineObservation* line = f.lines.emplace_back();
    line->start_px = a.cast<float>();
    line->end_px = b.cast<float>();
    const Eigen::Vector3d l = Eigen::Vector3d(a.x(), a.y(), 1).cross(Eigen::Vector3d(b.x(), b.y(), 1));
    line->l = l / l.head<2>().norm();
    line->length_px = float((b - a).norm());
    line->angle_rad = float(std::atan2(b.y() - a.y(), b.x() - a.x()));
    line->octave = 0;
    line->response = line->length_px;
    line->num_samples = uint8_t(samples);
    for (int s = 0; s < samples; ++s) {
      const Eigen::Vector3d X = A + (0.1 + 0.8 * s / std::max(1, samples - 1)) * (B - A);
      line->sample_P_cam[s] = X.cast<float>();
      line->sample_px[s] = camera.project(X).cast<float>();
    }
    line->has_3d = samples >= 2;
    line->line_point_cam = A.cast<float>();
    line->line_dir_cam = (B - A).normalized().cast<float>();
    (void)f.line_descriptors.push_back(sl.descriptor);
    view.line_segment.push_back(int(i));
  }
  f.keypoint_grid.setBounds(0, 0, float(camera.width), float(camera.height));
  f.keypoint_grid.build(int(f.keypoints.size()), [&f](int k) { return f.keypoints[k].px_undist; });
  return view;
}

// A frame of `n` keypoints with depth whose descriptors are unrelated to any scene (fresh random
// bits), at random places: nothing in it can be matched.
inline View unrelatedView(uint64_t seed, int n) {
  Scene noise = makeScene(seed, n, 0, Eigen::Isometry3d::Identity());
  return observe(noise, Eigen::Isometry3d::Identity());
}

// A map-start request for `view` at T_world_cam, filled the way the tracker fills it (every
// association empty). Built by hand so the mapper tests do not depend on the tracker.
inline std::unique_ptr<KeyframeRequest> newMapRequest(const View& view, const Eigen::Isometry3d& T_world_cam,
                                                      uint64_t sequence) {
  auto r = std::make_unique<KeyframeRequest>();
  r->start_new_map = true;
  r->frame_sequence = sequence;
  r->timestamp_s = 0.1 * double(sequence);
  r->T_world_cam = T_world_cam;
  r->features = *view.features;
  return r;
}

}  // namespace plumb::test

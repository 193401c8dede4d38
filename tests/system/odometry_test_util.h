#pragma once
// Helpers of the system tests: run the odometry over a FrameSource (or a synthetic scene) and
// collect the output trajectory, as `plumb run` does but without the tool layer.
#include <memory>
#include <string>
#include <vector>

#include "drivers/common/frame_source.h"
#include "drivers/synth/synthetic_scene.h"
#include "drivers/trajectory/evaluate.h"
#include "drivers/trajectory/trajectory_io.h"
#include "pipeline/odometry/odometry_system.h"

namespace plumb::test {

struct OdometryRun {
  std::vector<StampedPose> trajectory;
  OdometryStats stats;
  MapperStats mapper;
  std::size_t max_keyframes = 0, max_points = 0, max_lines = 0;  // largest counts seen per frame
};

inline void collect(OdometrySystem& system, OdometryRun* run) {
  system.drainFinishedFrames([run](const FinishedFrame& f) {
    StampedPose p;
    p.timestamp = f.timestamp_s;
    p.T_world_cam = f.T_world_cam;
    p.valid = f.valid;
    run->trajectory.push_back(p);
  });
  system.drainRetiredKeyframes([](const RetiredKeyframe&) {});
}

inline void trackCounts(const OdometrySystem& system, OdometryRun* run) {
  const MapCounts c = system.mapCounts();
  run->max_keyframes = std::max(run->max_keyframes, c.keyframes);
  run->max_points = std::max(run->max_points, c.points);
  run->max_lines = std::max(run->max_lines, c.lines);
}

inline OdometryRun runOdometry(FrameSource& source, const SystemOptions& options, long max_frames = -1) {
  OdometryRun run;
  auto system = std::make_unique<OdometrySystem>(source.camera(), options);
  RgbdImage image;
  for (long n = 0; max_frames < 0 || n < max_frames; ++n) {
    if (source.next(image) != SourceResult::kFrame) break;
    system->processImage(image);
    collect(*system, &run);
    trackCounts(*system, &run);
  }
  system->finish([&run](const FinishedFrame& f) {
    StampedPose p;
    p.timestamp = f.timestamp_s;
    p.T_world_cam = f.T_world_cam;
    p.valid = f.valid;
    run.trajectory.push_back(p);
  }, [](const RetiredKeyframe&) {});
  run.stats = system->stats();
  run.mapper = system->mapperStats();
  return run;
}

inline SynthOptions noisySynth(const std::string& preset, int frames) {
  SynthOptions o;
  o.preset = preset;
  o.frames = frames;
  o.depth_noise = true;
  o.depth_edge_holes = true;
  o.pixel_noise_sigma = 1.0;
  return o;
}

inline std::vector<StampedPose> groundTruth(const SyntheticScene& scene, int frames) {
  std::vector<StampedPose> gt;
  for (int i = 0; i < frames; ++i) {
    StampedPose p;
    p.timestamp = scene.timestamp(i);
    p.T_world_cam = scene.T_world_cam(i);
    gt.push_back(p);
  }
  return gt;
}

inline double ateRmse(const std::vector<StampedPose>& gt, const std::vector<StampedPose>& est) {
  AteResult ate;
  const Status st = evaluateAte(gt, est, AteOptions{}, &ate);
  return st.ok() ? ate.translation_m.rmse : 1e9;
}

inline SystemOptions systemOptions(bool lines) {
  SystemOptions o;
  o.odometry.tracker.use_lines = lines;
  return o;
}

}  // namespace plumb::test

// plumb_embed: plumb's odometry inside your own program, through the installed public API.
// Tracks 100 frames of a synthetic scene (rendered by plumb, exact ground truth known), checks that
// every frame was tracked and that the trajectory is right (ATE below 2 cm), then runs the same
// scene through the staged runtime (two threads per frame pipeline, `fast` mode) with a callback.
// Exit 0 when all holds.
#include <cstdio>
#include <memory>
#include <vector>

#include <plumb/odometry.h>

namespace api = plumb::api;

int fail(const std::string& what) {
  std::fprintf(stderr, "plumb_embed: FAILED: %s\n", what.c_str());
  return 1;
}

int main() {
  const char* scene = "synth:textured:1:100";
  std::unique_ptr<api::FrameReader> reader;
  api::Status st = api::FrameReader::open(scene, "", &reader);
  if (!st.ok) return fail(st.message);

  api::OdometryConfig config;
  config.camera = api::CameraSpec::fromValues(reader->camera());
  std::unique_ptr<api::Odometry> odometry;
  st = api::Odometry::create(config, &odometry);
  if (!st.ok) return fail(st.message);

  std::vector<uint8_t> bgr;
  std::vector<uint16_t> depth;
  std::vector<api::FinishedPose> trajectory;
  int tracked = 0, with_covariance = 0, frames = 0;
  for (;;) {
    double t = 0;
    bool got = false;
    st = reader->next(&bgr, &depth, &t, &got);
    if (!st.ok) return fail(st.message);
    if (!got) break;
    api::FrameView frame;
    frame.color = bgr.data();
    frame.depth = depth.data();
    frame.timestamp_s = t;
    frame.width = odometry->camera().width;
    frame.height = odometry->camera().height;
    api::TrackOutput out;
    st = odometry->track(frame, &out);
    if (!st.ok) return fail(st.message);
    ++frames;
    tracked += out.has_pose;
    with_covariance += out.covariance_valid;
    api::FinishedPose pose;
    while (odometry->popFinished(&pose)) trajectory.push_back(pose);
  }
  st = odometry->finish();
  if (!st.ok) return fail(st.message);
  api::FinishedPose pose;
  while (odometry->popFinished(&pose)) trajectory.push_back(pose);

  const api::Counters c = odometry->counters();
  const api::Evaluation e = api::evaluate(reader->groundTruth(frames), trajectory);
  std::printf("plumb_embed: %d frames, %d tracked (%d with covariance), %llu keyframes, %llu map segments, "
              "%llu relocalizations\n",
              frames, tracked, with_covariance, (unsigned long long)c.keyframes,
              (unsigned long long)c.map_segments, (unsigned long long)c.relocalizations);
  if (!e.ate_valid) return fail("no ATE: " + e.ate_error);
  std::printf("plumb_embed: ATE RMSE %.5f m over %zu poses (max %.5f m)\n", e.ate_m.rmse, e.ate_pairs, e.ate_m.max);
  if (frames != 100) return fail("expected 100 frames");
  if (tracked != 100) return fail("not every frame was tracked");
  if (trajectory.size() != 100) return fail("expected 100 finished poses");
  if (e.ate_m.rmse > 0.02) return fail("ATE above 2 cm");

  // The staged runtime through the same front door.
  api::RunConfig run;
  run.source = scene;
  run.mode = "fast";
  int poses = 0;
  api::RunSummary summary;
  st = api::runSource(run, [&](const api::TrackOutput& p) { poses += p.has_pose; }, nullptr, &summary);
  if (!st.ok) return fail(st.message);
  std::printf("plumb_embed: staged runtime (fast): %d poses, %.1f frames/s\n", poses, summary.frames_per_second);
  if (poses != 100) return fail("staged runtime: not every frame was tracked");
  std::printf("plumb_embed: OK\n");
  return 0;
}

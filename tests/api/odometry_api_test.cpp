// The public API (api/plumb/odometry.h) against the runner: Odometry::track() must give exactly the
// poses of runOdometry() in deterministic mode (runSource(), the staged runtime through the same
// front door), frame by frame and bit for bit, allocate nothing per frame after warm-up, and refuse
// bad input with a message.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include <memory>
#include <vector>

#include "api/plumb/odometry.h"
#include "platform/allocation_counter.h"

namespace plumb::api {
namespace {

struct Frames {
  CameraValues camera;
  std::vector<std::vector<uint8_t>> bgr;
  std::vector<std::vector<uint16_t>> depth;
  std::vector<double> t;
  std::vector<FinishedPose> ground_truth;
};

Frames loadFrames(const std::string& spec) {
  Frames f;
  std::unique_ptr<FrameReader> reader;
  const Status st = FrameReader::open(spec, "", &reader);
  EXPECT_TRUE(st.ok) << st.message;
  if (!st.ok) return f;
  f.camera = reader->camera();
  for (;;) {
    std::vector<uint8_t> bgr;
    std::vector<uint16_t> depth;
    double t = 0;
    bool got = false;
    const Status next = reader->next(&bgr, &depth, &t, &got);
    EXPECT_TRUE(next.ok) << next.message;
    if (!got || !next.ok) break;
    f.bgr.push_back(std::move(bgr));
    f.depth.push_back(std::move(depth));
    f.t.push_back(t);
  }
  f.ground_truth = reader->groundTruth(long(f.t.size()));
  return f;
}

FrameView view(const Frames& f, std::size_t i) {
  FrameView v;
  v.color = f.bgr[i].data();
  v.depth = f.depth[i].data();
  v.timestamp_s = f.t[i];
  v.width = f.camera.width;
  v.height = f.camera.height;
  return v;
}

std::unique_ptr<Odometry> makeOdometry(const CameraValues& camera, int output_delay = 60) {
  OdometryConfig config;
  config.camera = CameraSpec::fromValues(camera);
  config.output_delay_frames = output_delay;
  std::unique_ptr<Odometry> odometry;
  const Status st = Odometry::create(config, &odometry);
  EXPECT_TRUE(st.ok) << st.message;
  return odometry;
}

void expectSamePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, const std::string& where) {
  EXPECT_TRUE(a.matrix() == b.matrix()) << where << "\n" << a.matrix() << "\nvs\n" << b.matrix();
}

constexpr const char* kScene = "synth:textured:3:90";

TEST(OdometryApi, TrackGivesExactlyTheRunnersPosesAndFinishedTrajectory) {
  const Frames frames = loadFrames(kScene);
  ASSERT_EQ(frames.t.size(), 90u);

  // The runner, deterministic, through runSource().
  std::vector<TrackOutput> run_poses;
  std::vector<FinishedPose> run_finished;
  RunConfig config;
  config.source = kScene;
  RunSummary summary;
  const Status run = runSource(
      config, [&](const TrackOutput& p) { run_poses.push_back(p); },
      [&](const FinishedPose& p) { run_finished.push_back(p); }, &summary);
  ASSERT_TRUE(run.ok) << run.message;
  ASSERT_EQ(run_poses.size(), 90u);
  ASSERT_EQ(run_finished.size(), 90u);

  // Push-style, one frame per call.
  auto odometry = makeOdometry(frames.camera);
  std::vector<FinishedPose> finished;
  FinishedPose pose;
  for (std::size_t i = 0; i < frames.t.size(); ++i) {
    TrackOutput out;
    const Status st = odometry->track(view(frames, i), &out);
    ASSERT_TRUE(st.ok) << st.message;
    const TrackOutput& ref = run_poses[i];
    const std::string where = "frame " + std::to_string(i);
    EXPECT_EQ(out.sequence, ref.sequence) << where;
    EXPECT_EQ(out.timestamp_s, ref.timestamp_s) << where;
    EXPECT_EQ(out.state, ref.state) << where;
    EXPECT_EQ(out.has_pose, ref.has_pose) << where;
    expectSamePose(out.T_world_cam, ref.T_world_cam, where);
    EXPECT_EQ(out.covariance_valid, ref.covariance_valid) << where;
    EXPECT_TRUE(out.covariance == ref.covariance) << where;
    EXPECT_EQ(out.keyframe, ref.keyframe) << where;
    while (odometry->popFinished(&pose)) finished.push_back(pose);
  }
  // 60 frames held back for local BA until the end of the input.
  EXPECT_EQ(finished.size(), 30u);
  ASSERT_TRUE(odometry->finish().ok);
  while (odometry->popFinished(&pose)) finished.push_back(pose);
  ASSERT_EQ(finished.size(), run_finished.size());
  for (std::size_t i = 0; i < finished.size(); ++i) {
    EXPECT_EQ(finished[i].timestamp_s, run_finished[i].timestamp_s);
    EXPECT_EQ(finished[i].valid, run_finished[i].valid);
    expectSamePose(finished[i].T_world_cam, run_finished[i].T_world_cam, "finished " + std::to_string(i));
  }
  const Counters c = odometry->counters();
  EXPECT_EQ(c.frames, 90u);
  EXPECT_EQ(c.frames_ok, summary.counters.frames_ok);
  EXPECT_EQ(c.keyframes, summary.counters.keyframes);
  EXPECT_EQ(c.map_segments, 1u);
  EXPECT_EQ(c.relocalizations, 0u);
  EXPECT_GT(c.keyframes, 1u);

  // And the poses are right: exact synthetic ground truth, evaluated as `plumb eval` does.
  const Evaluation e = evaluate(frames.ground_truth, finished);
  ASSERT_TRUE(e.ate_valid) << e.ate_error;
  EXPECT_EQ(e.ate_pairs, 90u);
  EXPECT_LT(e.ate_m.rmse, 0.02);
}

TEST(OdometryApi, RgbInputGivesTheSamePosesAsBgr) {
  const Frames frames = loadFrames("synth:textured:5:12");
  auto bgr_odometry = makeOdometry(frames.camera);
  auto rgb_odometry = makeOdometry(frames.camera);
  for (std::size_t i = 0; i < frames.t.size(); ++i) {
    std::vector<uint8_t> rgb = frames.bgr[i];
    for (std::size_t p = 0; p + 2 < rgb.size(); p += 3) std::swap(rgb[p], rgb[p + 2]);
    FrameView v = view(frames, i);
    TrackOutput a, b;
    ASSERT_TRUE(bgr_odometry->track(v, &a).ok);
    v.color = rgb.data();
    v.format = PixelFormat::kRgb;
    ASSERT_TRUE(rgb_odometry->track(v, &b).ok);
    EXPECT_EQ(a.state, b.state);
    expectSamePose(a.T_world_cam, b.T_world_cam, "frame " + std::to_string(i));
  }
  EXPECT_EQ(bgr_odometry->counters().frames_ok + bgr_odometry->counters().frames_weak, 12u);
}

TEST(OdometryApi, NoHeapAllocationPerFrameAfterWarmup) {
  const Frames frames = loadFrames("synth:textured:7:70");
  auto odometry = makeOdometry(frames.camera);
  TrackOutput out;
  FinishedPose pose;
  uint64_t finished = 0;
  uint64_t allocations_at_warmup = 0;
  for (std::size_t i = 0; i < frames.t.size(); ++i) {
    if (i == 30) allocations_at_warmup = allocationCount();
    ASSERT_TRUE(odometry->track(view(frames, i), &out).ok);
    while (odometry->popFinished(&pose)) ++finished;
  }
  const uint64_t allocations = allocationCount() - allocations_at_warmup;
  EXPECT_EQ(allocations, 0u) << "over 40 frames after a 30-frame warm-up";
  EXPECT_EQ(finished, 10u);  // 70 frames, 60 held back
  EXPECT_TRUE(out.has_pose);
}

TEST(OdometryApi, BadInputIsRefusedWithAMessage) {
  const Frames frames = loadFrames("synth:textured:1:2");
  auto odometry = makeOdometry(frames.camera);
  FrameView v = view(frames, 0);
  TrackOutput out;
  v.width = 320;
  Status st = odometry->track(v, &out);
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.message.find("320x480"), std::string::npos) << st.message;
  v = view(frames, 0);
  v.depth = nullptr;
  st = odometry->track(v, &out);
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.message.find("depth"), std::string::npos) << st.message;
  v = view(frames, 0);
  v.color_stride = 10;
  EXPECT_FALSE(odometry->track(v, &out).ok);
  EXPECT_EQ(odometry->counters().frames, 0u);  // nothing ran
  ASSERT_TRUE(odometry->track(view(frames, 0), &out).ok);
  ASSERT_TRUE(odometry->finish().ok);
  st = odometry->track(view(frames, 1), &out);
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.message.find("finish"), std::string::npos) << st.message;
}

// CameraValues have no depth camera: a camera file describing one (unregistered depth) is refused
// rather than read as registered (docs/DATA_FORMATS.md "Unregistered depth").
TEST(OdometryApi, CameraFileWithAnUnregisteredDepthCameraIsRefused) {
  const std::string path = ::testing::TempDir() + "plumb_api_unregistered_depth.txt";
  std::ofstream(path) << "fx 525\nfy 525\ncx 319.5\ncy 239.5\ndepth_fx 575\ndepth_fy 575\ndepth_cx 314\n"
                         "depth_cy 243\ndepth_width 640\ndepth_height 480\ndepth_to_colour_qx 0\n"
                         "depth_to_colour_qy 0\ndepth_to_colour_qz 0\ndepth_to_colour_qw 1\n"
                         "depth_to_colour_tx 0.025\ndepth_to_colour_ty 0\ndepth_to_colour_tz 0\n";
  CameraValues values;
  const Status st = resolveCamera(CameraSpec::named(path), &values);
  std::remove(path.c_str());
  ASSERT_FALSE(st.ok);
  EXPECT_NE(st.message.find("not registered to colour"), std::string::npos) << st.message;
}

TEST(OdometryApi, CameraFromPresetFileOrValues) {
  CameraValues tum1;
  ASSERT_TRUE(resolveCamera(CameraSpec::named("tum1"), &tum1).ok);
  EXPECT_DOUBLE_EQ(tum1.fx, 517.306408);
  EXPECT_EQ(tum1.width, 640);
  EXPECT_EQ(tum1.rolling_shutter_readout_s, 0.025);  // every field of the camera crosses the API
  CameraValues unused;
  Status st = resolveCamera(CameraSpec::named("tum9"), &unused);
  EXPECT_FALSE(st.ok);
  CameraValues bad = tum1;
  bad.fx = 0;
  st = resolveCamera(CameraSpec::fromValues(bad), &unused);
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.message.find("focal"), std::string::npos) << st.message;
  OdometryConfig config;
  config.line_samples = 1;  // one sample fixes no 3D line: refused where the system is built
  std::unique_ptr<Odometry> odometry;
  EXPECT_FALSE(Odometry::create(config, &odometry).ok);
  EXPECT_EQ(odometry, nullptr);
}

}  // namespace
}  // namespace plumb::api

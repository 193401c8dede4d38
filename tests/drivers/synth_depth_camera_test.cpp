// The synthetic scene with a depth camera beside the colour camera (SynthOptions::depth_camera,
// drivers/synth/depth_camera_view.h):
//   - colour frames and ground truth are the registered scene's, byte for byte; depth differs and
//     has the depth camera's size;
//   - registered into the colour camera (pipeline/frontend/depth_registration.h), the offset depth
//     agrees with the depth the renderer draws from the colour camera itself; used as if it were
//     registered, it does not (the case the registration exists for);
//   - a folder written with it describes the depth camera in camera.txt, replays with its own
//     depth size, and is refused with a clear message under a camera without the depth camera;
//   - bad depth cameras are refused by validate().
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "dataset_test_support.h"
#include "drivers/dataset/camera_file.h"
#include "drivers/open/open_source.h"
#include "drivers/synth/synthetic_scene.h"
#include "pipeline/frontend/depth_registration.h"

namespace plumb {
namespace {

std::unique_ptr<SyntheticScene> makeScene(const std::string& preset, uint64_t seed, std::optional<DepthCamera> depth) {
  SynthOptions options;
  options.preset = preset;
  options.seed = seed;
  options.depth_camera = depth;
  std::unique_ptr<SyntheticScene> scene;
  const Status st = SyntheticScene::create(options, &scene);
  EXPECT_TRUE(st.ok()) << st.message();
  return scene;
}

TEST(SynthDepthCamera, ColourAndGroundTruthStayTheColourCamerasDepthIsTheDepthCameras) {
  const auto registered = makeScene("textured", 3, std::nullopt);
  const auto offset = makeScene("textured", 3, synthOffsetDepthCamera());
  const auto qvga = makeScene("textured", 3, synthOffsetDepthCameraQvga());
  ASSERT_TRUE(registered && offset && qvga);
  EXPECT_TRUE(registered->camera().depthRegistered());
  ASSERT_FALSE(offset->camera().depthRegistered());
  EXPECT_EQ(offset->camera().depth_camera->tx, 0.025);
  for (const int i : {0, 57}) {
    RgbdImage a, b, c;
    ASSERT_TRUE(registered->render(i, a).ok());
    ASSERT_TRUE(offset->render(i, b).ok());
    ASSERT_TRUE(qvga->render(i, c).ok());
    EXPECT_EQ(cv::countNonZero(a.bgr.reshape(1) != b.bgr.reshape(1)), 0);
    EXPECT_TRUE(registered->T_world_cam(i).matrix() == offset->T_world_cam(i).matrix());
    EXPECT_EQ(b.depth_raw.size(), cv::Size(640, 480));
    EXPECT_GT(cv::countNonZero(a.depth_raw != b.depth_raw), 100000);
    EXPECT_EQ(c.depth_raw.size(), cv::Size(320, 240));
  }
}

struct DepthAgreement {
  int truth = 0;    // colour pixels with a reading in the registered render
  int covered = 0;  // ... that also have one in the compared image
  int within_1cm = 0;
  double coverage() const { return truth ? double(covered) / truth : 0; }
  double agreement() const { return covered ? double(within_1cm) / covered : 0; }
};

DepthAgreement compare(const cv::Mat& truth, const cv::Mat& depth) {
  DepthAgreement r;
  for (int y = 0; y < truth.rows; ++y) {
    for (int x = 0; x < truth.cols; ++x) {
      const int t = truth.at<uint16_t>(y, x), d = depth.at<uint16_t>(y, x);
      if (t == 0) continue;
      ++r.truth;
      if (d == 0) continue;
      ++r.covered;
      r.within_1cm += std::abs(t - d) <= 50;  // 1 cm at 5000 units per metre
    }
  }
  return r;
}

// Noise-free frames of two presets. Registered offset depth: >= 97% of the pixels it covers
// within 1 cm of the colour camera's own depth; the rest are the pixels at depth edges, where a
// footprint's one sample stands for a pixel that straddles two surfaces. It covers the colour
// pixels the narrower depth camera sees (~85%). The same images taken as registered agree far
// less.
TEST(SynthDepthCamera, RegisteredOffsetDepthMatchesTheColourCamerasDepth) {
  for (const char* preset : {"textured", "low_texture"}) {
    const auto registered = makeScene(preset, 5, std::nullopt);
    const auto offset = makeScene(preset, 5, synthOffsetDepthCamera());
    const auto qvga = makeScene(preset, 5, synthOffsetDepthCameraQvga());
    ASSERT_TRUE(registered && offset && qvga);
    DepthRegistration registration(offset->camera());
    DepthRegistration registration_qvga(qvga->camera());
    for (const int i : {0, 120, 240}) {
      RgbdImage truth, raw, raw_qvga;
      ASSERT_TRUE(registered->render(i, truth).ok());
      ASSERT_TRUE(offset->render(i, raw).ok());
      ASSERT_TRUE(qvga->render(i, raw_qvga).ok());
      cv::Mat out, out_qvga;
      ASSERT_TRUE(registration.registerInto(raw.depth_raw, raw.depth_factor, out));
      ASSERT_TRUE(registration_qvga.registerInto(raw_qvga.depth_raw, raw_qvga.depth_factor, out_qvga));
      const DepthAgreement with = compare(truth.depth_raw, out);
      const DepthAgreement with_qvga = compare(truth.depth_raw, out_qvga);
      const DepthAgreement without = compare(truth.depth_raw, raw.depth_raw);
      std::printf("%s frame %d: registered %.1f%% within 1 cm (coverage %.1f%%), from 320x240 %.1f%% (%.1f%%), "
                  "used as if registered %.1f%% (%.1f%%)\n",
                  preset, i, 100 * with.agreement(), 100 * with.coverage(), 100 * with_qvga.agreement(),
                  100 * with_qvga.coverage(), 100 * without.agreement(), 100 * without.coverage());
      EXPECT_GE(with.agreement(), 0.97) << preset << " frame " << i;
      EXPECT_GE(with.coverage(), 0.80) << preset << " frame " << i;
      EXPECT_GE(with_qvga.agreement(), 0.94) << preset << " frame " << i;
      EXPECT_GE(with_qvga.coverage(), 0.80) << preset << " frame " << i;
      EXPECT_LT(without.agreement(), with.agreement() - 0.1) << preset << " frame " << i;
    }
  }
}

TEST(SynthDepthCamera, FolderDescribesTheDepthCameraAndReplaysAtItsSize) {
  testing::TempDir dir;
  SynthOptions options;
  options.frames = 3;
  options.depth_camera = synthOffsetDepthCameraQvga();
  ASSERT_TRUE(writeSynthDataset(options, dir.path()).ok());
  PinholeCamera camera;
  ASSERT_TRUE(readCameraFile(dir.file("camera.txt"), &camera).ok());
  ASSERT_FALSE(camera.depthRegistered());
  EXPECT_EQ(camera.depth_camera->width, 320);
  EXPECT_EQ(camera.depth_camera->qw, options.depth_camera->qw);

  std::unique_ptr<FrameSource> source;
  Status st = openFrameSource(dir.path(), "", &source);
  ASSERT_TRUE(st.ok()) << st.message();
  RgbdImage frame;
  ASSERT_EQ(source->next(frame), SourceResult::kFrame);
  EXPECT_EQ(frame.bgr.size(), cv::Size(640, 480));
  EXPECT_EQ(frame.depth_raw.size(), cv::Size(320, 240));

  // The same folder under a camera that says depth is registered: refused, not misread.
  PinholeCamera colour_only = camera;
  colour_only.depth_camera.reset();
  ASSERT_TRUE(writeCameraFile(dir.file("colour_only.txt"), colour_only).ok());
  st = openFrameSource(dir.path(), dir.file("colour_only.txt"), &source);
  ASSERT_TRUE(st.ok()) << st.message();
  ASSERT_EQ(source->next(frame), SourceResult::kError);
  EXPECT_NE(source->lastError().message().find("size 320x240, camera expects 640x480"), std::string::npos)
      << source->lastError().message();
}

TEST(SynthDepthCamera, ImplausibleOrDistortedDepthCamerasAreRefused) {
  SynthOptions options;
  options.depth_camera = synthOffsetDepthCamera();
  options.depth_camera->k1 = 0.1;
  Status st = validate(options);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("no distortion"), std::string::npos) << st.message();
  options.depth_camera = synthOffsetDepthCamera();
  options.depth_camera->tx = 25;  // millimetres
  st = validate(options);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("translation"), std::string::npos) << st.message();
}

}  // namespace
}  // namespace plumb

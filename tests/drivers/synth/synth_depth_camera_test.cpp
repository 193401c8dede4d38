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

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "tests/drivers/dataset_test_support.h"
#include "drivers/dataset/camera_file.h"
#include "drivers/open/open_source.h"
#include "drivers/synth/synthetic_scene.h"
#include "pipeline/frontend/depth_registration.h"

namespace plumb {
namespace {

std::unique_ptr<SyntheticScene> makeSceneWithDepth(const std::string& preset, uint64_t seed, std::optional<DepthCamera> depth) {
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
  const auto registered = makeSceneWithDepth("textured", 3, std::nullopt);
  const auto offset = makeSceneWithDepth("textured", 3, synthOffsetDepthCamera());
  const auto qvga = makeSceneWithDepth("textured", 3, synthOffsetDepthCameraQvga());
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
  int agree = 0;    // ... within the truth's range over the pixel's 3x3 neighbourhood +- 5 mm
  double coverage() const { return truth ? double(covered) / truth : 0; }
  double agreement() const { return covered ? double(agree) / covered : 0; }
};

// A registered pixel holds one depth sample whose footprint contains the pixel's centre, so on a
// slanted surface (the floor far away) it may read the depth of a point up to a pixel away: the
// truth's range over the 3x3 neighbourhood bounds it.
DepthAgreement compare(const cv::Mat& truth, const cv::Mat& depth) {
  DepthAgreement r;
  for (int y = 1; y + 1 < truth.rows; ++y) {
    for (int x = 1; x + 1 < truth.cols; ++x) {
      const int t = truth.at<uint16_t>(y, x), d = depth.at<uint16_t>(y, x);
      if (t == 0) continue;
      ++r.truth;
      if (d == 0) continue;
      ++r.covered;
      int lo = t, hi = t;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int n = truth.at<uint16_t>(y + dy, x + dx);
          if (n == 0) continue;
          lo = std::min(lo, n);
          hi = std::max(hi, n);
        }
      }
      r.agree += d >= lo - 25 && d <= hi + 25;  // 5 mm at 5000 units per metre
    }
  }
  return r;
}

// Noise-free frames. Registered offset depth agrees with the colour camera's own depth (above) at
// >= 99% of the pixels it covers, the rest being pixels at depth edges; it covers the colour pixels
// the narrower depth camera sees (~83%). The same images taken as registered agree far less.
TEST(SynthDepthCamera, RegisteredOffsetDepthMatchesTheColourCamerasDepth) {
  for (const char* preset : {"textured", "fast_rotation"}) {
    const auto registered = makeSceneWithDepth(preset, 5, std::nullopt);
    const auto offset = makeSceneWithDepth(preset, 5, synthOffsetDepthCamera());
    const auto qvga = makeSceneWithDepth(preset, 5, synthOffsetDepthCameraQvga());
    ASSERT_TRUE(registered && offset && qvga);
    DepthRegistration registration(offset->camera());
    DepthRegistration registration_qvga(qvga->camera());
    PinholeCamera no_extrinsic = offset->camera();  // the intrinsics alone: the extrinsic ignored
    no_extrinsic.depth_camera->qx = no_extrinsic.depth_camera->qy = no_extrinsic.depth_camera->qz = 0;
    no_extrinsic.depth_camera->qw = 1;
    no_extrinsic.depth_camera->tx = no_extrinsic.depth_camera->ty = no_extrinsic.depth_camera->tz = 0;
    DepthRegistration registration_no_extrinsic(no_extrinsic);
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
      cv::Mat out_no_extrinsic;
      ASSERT_TRUE(registration_no_extrinsic.registerInto(raw.depth_raw, raw.depth_factor, out_no_extrinsic));
      const DepthAgreement ignored = compare(truth.depth_raw, out_no_extrinsic);
      std::printf("%s frame %d: registered %.2f%% agree (coverage %.1f%%), from 320x240 %.2f%% (%.1f%%), "
                  "extrinsic ignored %.1f%%, used as if registered %.1f%% (%.1f%%)\n",
                  preset, i, 100 * with.agreement(), 100 * with.coverage(), 100 * with_qvga.agreement(),
                  100 * with_qvga.coverage(), 100 * ignored.agreement(), 100 * without.agreement(),
                  100 * without.coverage());
      EXPECT_GE(with.agreement(), 0.995) << preset << " frame " << i;
      EXPECT_GE(with.coverage(), 0.80) << preset << " frame " << i;
      EXPECT_GE(with_qvga.agreement(), 0.99) << preset << " frame " << i;
      EXPECT_LT(ignored.agreement(), 0.9) << preset << " frame " << i;
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

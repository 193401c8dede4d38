// Camera presets, camera files and the lens model on the presets' real values.
#include "drivers/dataset/camera_presets.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/drivers/dataset_test_support.h"
#include "drivers/dataset/camera_file.h"

namespace plumb {
namespace {

using testing::TempDir;

TEST(CameraPresets, KnownPresetsMatchTheBenchmarkCalibration) {
  PinholeCamera camera;
  ASSERT_TRUE(cameraFromSpec("tum1", &camera).ok());
  EXPECT_DOUBLE_EQ(camera.fx, 517.306408);
  EXPECT_DOUBLE_EQ(camera.cy, 255.313989);
  EXPECT_DOUBLE_EQ(camera.k3, 1.163314);
  EXPECT_DOUBLE_EQ(camera.depth_factor, 5000.0);
  EXPECT_TRUE(camera.hasDistortion());

  ASSERT_TRUE(cameraFromSpec("tum2", &camera).ok());
  EXPECT_DOUBLE_EQ(camera.fx, 520.908620);
  EXPECT_NEAR(camera.k1, 0.2312, 1e-4);
  EXPECT_NEAR(camera.k2, -0.7849, 1e-4);
  EXPECT_NEAR(camera.p1, -0.0033, 1e-4);
  EXPECT_NEAR(camera.p2, -0.0001, 1e-4);
  EXPECT_NEAR(camera.k3, 0.9172, 1e-4);

  ASSERT_TRUE(cameraFromSpec("tum3", &camera).ok());
  EXPECT_DOUBLE_EQ(camera.fy, 539.2);
  EXPECT_FALSE(camera.hasDistortion());

  ASSERT_TRUE(cameraFromSpec("icl", &camera).ok());
  EXPECT_DOUBLE_EQ(camera.fx, 481.2);
  EXPECT_DOUBLE_EQ(camera.fy, -480.0);
  EXPECT_EQ(camera.width, 640);
  EXPECT_EQ(camera.height, 480);
}

TEST(CameraPresets, UnknownSpecIsAFileThatDoesNotExist) {
  PinholeCamera camera;
  const Status st = cameraFromSpec("tum9", &camera);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("tum9"), std::string::npos) << st.message();
  EXPECT_FALSE(cameraFromSpec("", &camera).ok());
}

TEST(CameraModel, NegativeFyProjectUnprojectRoundTrip) {
  PinholeCamera icl;
  ASSERT_TRUE(cameraPreset("icl", &icl).ok());
  for (double u : {0.0, 100.5, 319.5, 639.0}) {
    for (double v : {0.0, 50.25, 239.5, 479.0}) {
      const Eigen::Vector3d P_cam = icl.unproject(u, v, 2.5);
      EXPECT_DOUBLE_EQ(P_cam.z(), 2.5);
      const Eigen::Vector2d uv = icl.project(P_cam);
      EXPECT_NEAR(uv.x(), u, 1e-9);
      EXPECT_NEAR(uv.y(), v, 1e-9);
    }
  }
  // With fy < 0 a point above the optical axis in camera y (negative y) lands below the centre row.
  EXPECT_GT(icl.project(Eigen::Vector3d(0, -0.5, 2)).y(), icl.cy);
}

TEST(CameraModel, UndistortInvertsDistortOverTheWholeImageTum1AndTum2) {
  for (const char* preset : {"tum1", "tum2"}) {
    PinholeCamera camera;
    ASSERT_TRUE(cameraPreset(preset, &camera).ok());
    double worst_px = 0;
    for (int v = 0; v < camera.height; v += 8) {
      for (int u = 0; u < camera.width; u += 8) {
        // Distorted pixel -> ideal -> distorted again must come back to where it started.
        const Eigen::Vector2d ideal = camera.undistortPoint(u, v);
        const Eigen::Vector2d back = camera.distortPoint(ideal.x(), ideal.y());
        worst_px = std::max(worst_px, (back - Eigen::Vector2d(u, v)).norm());
      }
    }
    EXPECT_LT(worst_px, 1e-3) << preset;
    // And the other way: an ideal pixel whose distorted image lies in the image (where keypoints
    // can come from), distorted, undistorts back to itself.
    worst_px = 0;
    for (int v = 0; v < camera.height; v += 8) {
      for (int u = 0; u < camera.width; u += 8) {
        const Eigen::Vector2d distorted = camera.distortPoint(u, v);
        if (!camera.inImage(distorted.x(), distorted.y())) continue;
        const Eigen::Vector2d back = camera.undistortPoint(distorted.x(), distorted.y());
        worst_px = std::max(worst_px, (back - Eigen::Vector2d(u, v)).norm());
      }
    }
    EXPECT_LT(worst_px, 1e-3) << preset;
    // The corners really are moved (the test would pass trivially with no distortion).
    EXPECT_GT((camera.undistortPoint(0, 0) - Eigen::Vector2d(0, 0)).norm(), 1.0) << preset;
  }
}

TEST(CameraFile, WriteReadRoundTripIsExact) {
  TempDir dir;
  PinholeCamera camera;
  ASSERT_TRUE(cameraPreset("tum1", &camera).ok());
  camera.width = 320;
  camera.height = 240;
  camera.cx = 159.25;  // inside the smaller image (a principal point off the image is refused)
  camera.cy = 119.75;
  camera.baseline_m = 0.075;
  ASSERT_TRUE(writeCameraFile(dir.file("camera.txt"), camera).ok());
  PinholeCamera back;
  ASSERT_TRUE(cameraFromSpec(dir.file("camera.txt"), &back).ok());
  EXPECT_EQ(back.fx, camera.fx);
  EXPECT_EQ(back.fy, camera.fy);
  EXPECT_EQ(back.k2, camera.k2);
  EXPECT_EQ(back.width, 320);
  EXPECT_EQ(back.height, 240);
  EXPECT_EQ(back.baseline_m, 0.075);
  EXPECT_EQ(back.rolling_shutter_readout_s, camera.rolling_shutter_readout_s);
  EXPECT_GT(back.rolling_shutter_readout_s, 0.0);  // the Kinect preset has a rolling shutter
}

TEST(CameraFile, MinimalFileHasNoDistortionAndDefaults) {
  TempDir dir;
  const std::string path = dir.write("cam.txt",
                                     "# ICL-like\n"
                                     "fx 481.2\n fy -480\ncx 319.5\ncy 239.5   # centre\n\n");
  PinholeCamera camera;
  const Status st = cameraFromSpec(path, &camera);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_DOUBLE_EQ(camera.fy, -480.0);
  EXPECT_DOUBLE_EQ(camera.cy, 239.5);
  EXPECT_FALSE(camera.hasDistortion());
  EXPECT_EQ(camera.width, 640);
  EXPECT_DOUBLE_EQ(camera.depth_factor, 5000.0);
}

// Each bad file must fail with a message that names the file and the offending line.
void expectCameraFileError(const std::string& content, const std::string& expected_location,
                           const std::string& expected_words) {
  TempDir dir;
  const std::string path = dir.write("camera.txt", content);
  PinholeCamera camera;
  const Status st = cameraFromSpec(path, &camera);
  ASSERT_FALSE(st.ok()) << content;
  EXPECT_NE(st.message().find(path + expected_location), std::string::npos) << st.message();
  EXPECT_NE(st.message().find(expected_words), std::string::npos) << st.message();
}

TEST(CameraFile, NanIntrinsicNamesFileAndLine) {
  expectCameraFileError("fx 500\nfy nan\ncx 320\ncy 240\n", ":2", "not finite");
}

TEST(CameraFile, ZeroFocalLengthNamesFileAndLine) {
  expectCameraFileError("fx 0\nfy 500\ncx 320\ncy 240\n", ":1", "zero");
  expectCameraFileError("fx 500\n# comment\nfy 0.0\ncx 320\ncy 240\n", ":3", "zero");
}

TEST(CameraFile, UnparsableUnknownRepeatedAndMissingKeys) {
  expectCameraFileError("fx 500\nfy 5O0\ncx 320\ncy 240\n", ":2", "not a number");
  expectCameraFileError("fx 500\nfy 500\nfz 1\ncx 320\ncy 240\n", ":3", "unknown key");
  expectCameraFileError("fx 500\nfy 500\nfx 501\ncx 320\ncy 240\n", ":3", "repeated");
  expectCameraFileError("fx 500 600\n", ":1", "key value");
  expectCameraFileError("fx 500\nfy 500\ncx 320\ncy 240\nwidth -640\n", ":5", "positive");
  expectCameraFileError("fx 500\nfy 500\ncx 320\n", "", "missing required key 'cy'");
  expectCameraFileError("", "", "missing required key");
}

TEST(CameraFile, MissingFileIsNamed) {
  PinholeCamera camera;
  const Status st = cameraFromSpec("/nonexistent/plumb/camera.txt", &camera);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("/nonexistent/plumb/camera.txt"), std::string::npos) << st.message();
}

}  // namespace
}  // namespace plumb

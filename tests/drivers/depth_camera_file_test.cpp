// Unregistered depth in camera files (docs/DATA_FORMATS.md "Unregistered depth"): the keys, the
// exact round trip, the all-or-nothing rule, each plausibility bound with its message; presets
// stay registered; recordings keep the depth camera (format version 3) or are replayed under one.
#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <utility>

#include "dataset_test_support.h"
#include "drivers/dataset/camera_file.h"
#include "drivers/dataset/camera_presets.h"
#include "drivers/recording/recording_source.h"
#include "drivers/recording/recording_writer.h"

namespace plumb {
namespace {

using testing::TempDir;

const char* const kColour = "fx 525\nfy 525\ncx 319.5\ncy 239.5\n";
// A Kinect-like depth camera 2.5 cm beside the colour camera, turned 0.54 degrees.
const char* const kDepth =
    "depth_fx 575\ndepth_fy 575\ndepth_cx 314\ndepth_cy 243\ndepth_width 640\ndepth_height 480\n"
    "depth_to_colour_qx 0.0015\ndepth_to_colour_qy -0.004\ndepth_to_colour_qz 0.002\n"
    "depth_to_colour_qw 0.99998775\ndepth_to_colour_tx 0.025\ndepth_to_colour_ty 0.001\n"
    "depth_to_colour_tz -0.002\n";

Status readText(const std::string& text, PinholeCamera* camera, std::string* path_out = nullptr) {
  static int counter = 0;
  TempDir dir;
  const std::string path = dir.write("camera" + std::to_string(counter++) + ".txt", text);
  if (path_out) *path_out = path;
  return readCameraFile(path, camera);
}

// kDepth with the values of some keys replaced.
std::string depthWith(std::initializer_list<std::pair<std::string, std::string>> values) {
  std::string text = kDepth;
  for (const auto& [key, value] : values) {
    const std::size_t at = text.find(key + " ");
    const std::size_t end = text.find('\n', at);
    text.replace(at, end - at, key + " " + value);
  }
  return text;
}
std::string depthWith(const std::string& key, const std::string& value) { return depthWith({{key, value}}); }

void expectBoundMessage(const std::string& depth_text, const std::string& words) {
  PinholeCamera camera;
  const Status st = readText(std::string(kColour) + depth_text, &camera);
  ASSERT_FALSE(st.ok()) << depth_text;
  EXPECT_NE(st.message().find(words), std::string::npos) << st.message();
}

TEST(DepthCameraFile, KeysAreReadAndRoundTripBitForBit) {
  PinholeCamera camera;
  const Status st = readText(std::string(kColour) + kDepth, &camera);
  ASSERT_TRUE(st.ok()) << st.message();
  ASSERT_FALSE(camera.depthRegistered());
  const DepthCamera& d = *camera.depth_camera;
  EXPECT_EQ(d.fx, 575);
  EXPECT_EQ(d.cy, 243);
  EXPECT_EQ(d.width, 640);
  EXPECT_EQ(d.qw, 0.99998775);  // kept as written (normalised only when used)
  EXPECT_EQ(d.tx, 0.025);
  EXPECT_NEAR(d.rotationDeg(), 0.54, 0.01);
  EXPECT_NEAR(d.T_colour_depth().translation().z(), -0.002, 1e-15);

  camera.depth_camera->k1 = 0.1 / 3;  // values without a short decimal form
  camera.depth_camera->qx = 1e-3 / 7;
  TempDir dir;
  ASSERT_TRUE(writeCameraFile(dir.file("c.txt"), camera).ok());
  PinholeCamera back;
  ASSERT_TRUE(readCameraFile(dir.file("c.txt"), &back).ok());
  ASSERT_TRUE(back.depth_camera.has_value());
  const DepthCamera& a = *camera.depth_camera;
  const DepthCamera& b = *back.depth_camera;
  for (const auto field : {&DepthCamera::fx, &DepthCamera::fy, &DepthCamera::cx, &DepthCamera::cy, &DepthCamera::k1,
                           &DepthCamera::k2, &DepthCamera::p1, &DepthCamera::p2, &DepthCamera::k3, &DepthCamera::qx,
                           &DepthCamera::qy, &DepthCamera::qz, &DepthCamera::qw, &DepthCamera::tx, &DepthCamera::ty,
                           &DepthCamera::tz}) {
    EXPECT_EQ(a.*field, b.*field);
  }
  EXPECT_EQ(b.width, a.width);
  EXPECT_EQ(b.height, a.height);
  EXPECT_EQ(back.depthWidth(), 640);
}

TEST(DepthCameraFile, WithoutDepthKeysDepthIsRegisteredAndPresetsToo) {
  PinholeCamera camera;
  ASSERT_TRUE(readText(kColour, &camera).ok());
  EXPECT_TRUE(camera.depthRegistered());
  EXPECT_EQ(camera.depthWidth(), camera.width);
  for (const char* preset : {"tum1", "tum2", "tum3", "icl"}) {
    ASSERT_TRUE(cameraFromSpec(preset, &camera).ok());
    EXPECT_TRUE(camera.depthRegistered()) << preset;
  }
  // A registered camera's file has no depth keys at all.
  TempDir dir;
  ASSERT_TRUE(writeCameraFile(dir.file("c.txt"), camera).ok());
  EXPECT_EQ(testing::readWholeFile(dir.file("c.txt")).find("depth_fx"), std::string::npos);
}

TEST(DepthCameraFile, OneDepthKeyNeedsAllOfThem) {
  PinholeCamera camera;
  std::string path;
  Status st = readText(std::string(kColour) + "depth_fx 575\n", &camera, &path);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find(path), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("missing key 'depth_cx'"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("line 5"), std::string::npos) << st.message();
  // Leaving out the translation would silently make it zero: refused.
  std::string text = kDepth;
  text.erase(text.find("depth_to_colour_tz"));
  st = readText(std::string(kColour) + text, &camera);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("'depth_to_colour_tz'"), std::string::npos) << st.message();
  // Distortion is optional; the per-key checks apply as for the colour camera.
  expectBoundMessage(depthWith("depth_fx", "0"), "depth_fx is zero");
  expectBoundMessage(depthWith("depth_width", "-1"), "depth_width must be positive");
  expectBoundMessage(depthWith("depth_cy", "inf"), "depth_cy is not finite");
  expectBoundMessage(std::string(kDepth) + "depth_fx 575\n", "repeated");
}

TEST(DepthCameraFile, EachPlausibilityBoundHasItsMessage) {
  expectBoundMessage(depthWith("depth_to_colour_tx", "25"), "translation is 25 m long");
  expectBoundMessage(depthWith("depth_to_colour_tx", "25"), "not millimetres");
  expectBoundMessage(depthWith("depth_to_colour_qw", "0.5"), "unit quaternion");
  // 40 degrees about y: quaternion (0, sin 20, 0, cos 20).
  expectBoundMessage(depthWith({{"depth_to_colour_qx", "0"}, {"depth_to_colour_qy", "0.34202014"},
                                {"depth_to_colour_qz", "0"}, {"depth_to_colour_qw", "0.93969262"}}),
                     "rotation is 40.0 degrees");
  expectBoundMessage(depthWith("depth_fx", "5"), "field of view");
  expectBoundMessage(depthWith("depth_fx", "57500"), "field of view");
  expectBoundMessage(depthWith("depth_cx", "700"), "principal point (700.0, 243.0) lies outside");
  expectBoundMessage(depthWith("depth_width", "9000"), "exceeds 8192");
  // Plausible alone, but pointing away from the colour image: principal point at the left edge
  // and 14 degrees about y put the depth view's centre beside the colour image.
  const std::string away = depthWith({{"depth_cx", "0"}, {"depth_to_colour_qx", "0"}, {"depth_to_colour_qy", "0.121869"},
                                      {"depth_to_colour_qz", "0"}, {"depth_to_colour_qw", "0.992546"}});
  expectBoundMessage(away, "falls outside the colour image");
}

// A recording made with an unregistered depth camera is a version 3 file: the depth camera is in
// its header (bit for bit) and its depth images keep their own size; registered cameras still
// write version 2.
TEST(DepthCameraFile, RecordingsKeepTheDepthCameraAndItsImageSize) {
  PinholeCamera camera;
  ASSERT_TRUE(readText(std::string(kColour) + depthWith({{"depth_fx", "287.5"}, {"depth_fy", "287.5"},
                                                         {"depth_cx", "157"}, {"depth_cy", "121.5"},
                                                         {"depth_width", "320"}, {"depth_height", "240"}}),
                       &camera)
                  .ok());
  TempDir dir;
  for (const ImageCodec codec : {ImageCodec::kRaw, ImageCodec::kPng}) {
    SCOPED_TRACE(codec == ImageCodec::kRaw ? "raw" : "png");
    const std::string path = dir.file(codec == ImageCodec::kRaw ? "raw.plumbrec" : "png.plumbrec");
    RecordingWriterOptions options;
    options.colour_codec = options.depth_codec = codec;
    {
      std::unique_ptr<RecordingWriter> writer;
      ASSERT_TRUE(RecordingWriter::open(path, camera, options, &writer).ok());
      RgbdImage frame;
      frame.bgr = cv::Mat(480, 640, CV_8UC3, cv::Scalar(1, 2, 3));
      frame.depth_raw = cv::Mat(480, 640, CV_16UC1, cv::Scalar(7000));  // the colour size: refused
      frame.timestamp_s = frame.depth_timestamp_s = 1.0;
      const Status refused = writer->append(frame);
      ASSERT_FALSE(refused.ok());
      EXPECT_NE(refused.message().find("320x240"), std::string::npos) << refused.message();
      frame.depth_raw = cv::Mat(240, 320, CV_16UC1, cv::Scalar(7000));
      frame.depth_raw.at<uint16_t>(239, 319) = 1234;
      ASSERT_TRUE(writer->append(frame).ok());
      ASSERT_TRUE(writer->close().ok());
    }
    EXPECT_EQ(testing::readWholeFile(path)[8], 3);  // version 3
    std::unique_ptr<RecordingSource> source;
    const Status st = RecordingSource::open(path, &source);
    ASSERT_TRUE(st.ok()) << st.message();
    ASSERT_FALSE(source->camera().depthRegistered());
    const DepthCamera& a = *camera.depth_camera;
    const DepthCamera& b = *source->camera().depth_camera;
    for (const auto field : {&DepthCamera::fx, &DepthCamera::fy, &DepthCamera::cx, &DepthCamera::cy, &DepthCamera::qx,
                             &DepthCamera::qy, &DepthCamera::qz, &DepthCamera::qw, &DepthCamera::tx, &DepthCamera::ty,
                             &DepthCamera::tz}) {
      EXPECT_EQ(a.*field, b.*field);
    }
    EXPECT_EQ(b.width, 320);
    RgbdImage out;
    ASSERT_EQ(source->next(out), SourceResult::kFrame);
    ASSERT_EQ(out.depth_raw.size(), cv::Size(320, 240));
    EXPECT_EQ(out.depth_raw.at<uint16_t>(239, 319), 1234);
    EXPECT_EQ(out.depth_raw.at<uint16_t>(0, 0), 7000);
    EXPECT_EQ(out.bgr.size(), cv::Size(640, 480));
    EXPECT_EQ(source->next(out), SourceResult::kEndOfStream);
    EXPECT_EQ(source->stats().chunks_skipped, 0u);
  }
  // A registered camera still writes version 2.
  PinholeCamera registered = camera;
  registered.depth_camera.reset();
  std::unique_ptr<RecordingWriter> writer;
  ASSERT_TRUE(RecordingWriter::open(dir.file("v2.plumbrec"), registered, RecordingWriterOptions(), &writer).ok());
  ASSERT_TRUE(writer->close().ok());
  EXPECT_EQ(testing::readWholeFile(dir.file("v2.plumbrec"))[8], 2);
}

// A recording of colour-sized unregistered depth (written under its colour camera) replays with
// the depth camera given as its camera; a depth camera of another size cannot have made it.
TEST(DepthCameraFile, RecordingReplaysUnderADepthCameraOfItsSizeOnly) {
  PinholeCamera unregistered;
  ASSERT_TRUE(readText(std::string(kColour) + kDepth, &unregistered).ok());
  PinholeCamera colour_only = unregistered;
  colour_only.depth_camera.reset();
  TempDir dir;
  {
    std::unique_ptr<RecordingWriter> writer;
    ASSERT_TRUE(RecordingWriter::open(dir.file("r.plumbrec"), colour_only, RecordingWriterOptions(), &writer).ok());
    RgbdImage frame;
    frame.bgr = cv::Mat(480, 640, CV_8UC3, cv::Scalar(1, 2, 3));
    frame.depth_raw = cv::Mat(480, 640, CV_16UC1, cv::Scalar(7000));
    frame.timestamp_s = frame.depth_timestamp_s = 1.0;
    ASSERT_TRUE(writer->append(frame).ok());
    ASSERT_TRUE(writer->close().ok());
  }
  std::unique_ptr<RecordingSource> source;
  ASSERT_TRUE(RecordingSource::open(dir.file("r.plumbrec"), &source).ok());
  ASSERT_TRUE(source->overrideCamera(unregistered).ok());
  EXPECT_FALSE(source->camera().depthRegistered());
  RgbdImage out;
  ASSERT_EQ(source->next(out), SourceResult::kFrame);
  EXPECT_EQ(out.depth_raw.at<uint16_t>(10, 10), 7000);

  PinholeCamera qvga_depth = unregistered;
  qvga_depth.depth_camera = std::nullopt;
  ASSERT_TRUE(readText(std::string(kColour) + depthWith({{"depth_fx", "287.5"}, {"depth_fy", "287.5"},
                                                         {"depth_cx", "157"}, {"depth_cy", "121.5"},
                                                         {"depth_width", "320"}, {"depth_height", "240"}}),
                       &qvga_depth)
                  .ok());
  ASSERT_TRUE(RecordingSource::open(dir.file("r.plumbrec"), &source).ok());
  const Status st = source->overrideCamera(qvga_depth);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("depth camera is 320x240 but the recording's depth images are 640x480"),
            std::string::npos)
      << st.message();
}

}  // namespace
}  // namespace plumb

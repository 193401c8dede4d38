// TUM folder -> recording -> TUM folder keeps every pixel and timestamp; source specifications
// of recordings and sensors open through openFrameSource with clear errors.
#include <gtest/gtest.h>

#include <filesystem>

#include "drivers/open/open_source.h"
#include "drivers/dataset/camera_presets.h"
#include "drivers/dataset/tum_dataset.h"
#include "drivers/openni2/openni2_source.h"
#include "drivers/recording/recording_source.h"
#include "drivers/recording/recording_writer.h"
#include "drivers/recording/tum_folder_writer.h"
#include "tests/devices/device_test_util.h"

namespace plumb {
namespace {

TEST(TumFolderWriter, TimestampsReadBackAsTheSameDouble) {
  EXPECT_EQ(formatTimestamp(1305031102.175304), "1305031102.175304");
  EXPECT_EQ(formatTimestamp(1000.0), "1000.000000");
  const double awkward = 1000.0 + 1.0 / 30.0;  // synthetic scenes: 1000 + i / fps
  EXPECT_EQ(std::strtod(formatTimestamp(awkward).c_str(), nullptr), awkward);
}

TEST(TumFolderWriter, FolderRecordingFolderRoundTripIsExact) {
  test::ScratchDir dir("convert");
  const PinholeCamera camera = test::smallCamera(20, 10);
  std::vector<RgbdImage> frames = test::makeNoiseFrames(21, 20, 10, 4);
  for (std::size_t i = 0; i < frames.size(); ++i) {  // synthetic-style stamps need > 6 decimals
    frames[i].timestamp_s = 1000.0 + static_cast<double>(i) / 30.0;
    frames[i].depth_timestamp_s = frames[i].timestamp_s + 0.002;
  }
  {
    std::unique_ptr<TumFolderWriter> writer;
    ASSERT_TRUE(TumFolderWriter::open(dir.file("a"), camera, &writer).ok());
    for (const RgbdImage& f : frames) ASSERT_TRUE(writer->append(f).ok());
    ASSERT_TRUE(writer->close().ok());
  }
  std::unique_ptr<TumFolderWriter> again;
  EXPECT_FALSE(TumFolderWriter::open(dir.file("a"), camera, &again).ok()) << "never overwrite";

  // Folder -> recording (camera from the folder's camera.txt) -> folder -> replay.
  std::unique_ptr<FrameSource> folder;
  const Status opened = openFrameSource(dir.file("a"), "", &folder);
  ASSERT_TRUE(opened.ok()) << opened.message();
  EXPECT_EQ(folder->camera().fy, camera.fy);
  {
    std::unique_ptr<RecordingWriter> rec;
    ASSERT_TRUE(RecordingWriter::open(dir.file("a.plumbrec"), folder->camera(), {}, &rec).ok());
    RgbdImage f;
    while (folder->next(f) == SourceResult::kFrame) ASSERT_TRUE(rec->append(f).ok());
    ASSERT_TRUE(rec->close().ok());
  }
  std::unique_ptr<FrameSource> recording;
  ASSERT_TRUE(openFrameSource(dir.file("a.plumbrec"), "", &recording).ok());
  {
    std::unique_ptr<TumFolderWriter> writer;
    ASSERT_TRUE(TumFolderWriter::open(dir.file("b"), recording->camera(), &writer).ok());
    RgbdImage f;
    while (recording->next(f) == SourceResult::kFrame) ASSERT_TRUE(writer->append(f).ok());
  }
  std::unique_ptr<TumDatasetSource> replay;
  const Status replayed = TumDatasetSource::open(dir.file("b"), camera, &replay);
  ASSERT_TRUE(replayed.ok()) << replayed.message();
  ASSERT_TRUE(replay->usedAssociationsFile());
  RgbdImage out;
  for (const RgbdImage& f : frames) {
    ASSERT_EQ(replay->next(out), SourceResult::kFrame);
    EXPECT_EQ(out.timestamp_s, f.timestamp_s);
    EXPECT_EQ(out.depth_timestamp_s, f.depth_timestamp_s);
    EXPECT_TRUE(test::sameImage(out.bgr, f.bgr));
    EXPECT_TRUE(test::sameImage(out.depth_raw, f.depth_raw));
  }
  EXPECT_EQ(replay->next(out), SourceResult::kEndOfStream);
}

TEST(SensorSpecs, RecordingsOpenThroughOpenFrameSourceAndTheCameraCanBeOverridden) {
  test::ScratchDir dir("specs");
  const std::string path = dir.file("r.plumbrec");
  {
    std::unique_ptr<RecordingWriter> rec;
    ASSERT_TRUE(RecordingWriter::open(path, test::smallCamera(640, 480), {}, &rec).ok());
  }
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(openFrameSource(path, "", &source).ok());
  EXPECT_EQ(source->describe(), "plumbrec:" + path);
  EXPECT_EQ(source->camera().fx, 50.5);
  ASSERT_TRUE(openFrameSource(path, "tum1", &source).ok());
  EXPECT_NEAR(source->camera().fx, 517.306408, 1e-9);
  const Status missing = openFrameSource(dir.file("none.plumbrec"), "", &source);
  EXPECT_NE(missing.message().find("none.plumbrec"), std::string::npos) << missing.message();
}

TEST(SensorSpecs, PacedWrapsAnySpec) {
  test::ScratchDir dir("paced");
  const std::string path = dir.file("p.plumbrec");
  {
    std::unique_ptr<RecordingWriter> rec;
    ASSERT_TRUE(RecordingWriter::open(path, test::smallCamera(8, 6), {}, &rec).ok());
    for (const RgbdImage& f : test::makeNoiseFrames(2, 8, 6, 3)) ASSERT_TRUE(rec->append(f).ok());
  }
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(openFrameSource("paced@4:" + path, "", &source).ok());
  EXPECT_EQ(source->describe(), "paced(plumbrec:" + path + ")");
  RgbdImage out;
  int frames = 0;
  while (source->next(out) == SourceResult::kFrame) ++frames;  // 2 x 33 ms / 4: ~17 ms total
  EXPECT_EQ(frames, 3);
  EXPECT_EQ(openFrameSource("paced@fast:" + path, "", &source).message(),
            "paced@fast:" + path + ": speed 'fast' is not a positive number");
  EXPECT_FALSE(openFrameSource("paced:", "", &source).ok());
}

TEST(SensorSpecs, SensorSpecErrorsAreClear) {
  std::unique_ptr<FrameSource> source;
  EXPECT_EQ(openFrameSource("v4l2:/dev/video0", "", &source).message(),
            "v4l2:/dev/video0: V4L2 reports no intrinsics; pass a camera file or preset");
  EXPECT_EQ(openFrameSource("v4l2:/dev/video0:rgb3", "tum1", &source).message(),
            "v4l2:/dev/video0:rgb3: unknown colour format 'rgb3' (yuyv mjpeg grey)");
  const Status no_node = openFrameSource("v4l2:/dev/nonexistent-video,/dev/video1:mjpeg", "tum1", &source);
  EXPECT_EQ(no_node.message(), "/dev/nonexistent-video: open failed: No such file or directory");
  // The camera's USB identity is checked before any device is opened; a good one reaches the node.
#ifdef PLUMB_HAVE_LIBUSB
  EXPECT_EQ(openFrameSource("v4l2:/dev/nonexistent-video@usb=8086", "tum1", &source).message(),
            "v4l2:/dev/nonexistent-video@usb=8086: expected @usb=VID:PID in hex, e.g. @usb=8086:0b07");
  EXPECT_EQ(openFrameSource("v4l2:/dev/nonexistent-video:yuyv@usb=8086:0b07", "tum1", &source).message(),
            "/dev/nonexistent-video: open failed: No such file or directory");
#else
  EXPECT_NE(openFrameSource("v4l2:/dev/nonexistent-video@usb=8086:0b07", "tum1", &source).message().find("without"),
            std::string::npos);
#endif
#ifdef PLUMB_HAVE_OPENNI2
  std::vector<OpenNI2DeviceInfo> devices;
  if (listOpenNI2Devices(&devices).ok() && devices.empty()) {
    EXPECT_EQ(openFrameSource("openni2:first", "", &source).message(),
              "openni2: no OpenNI2 device connected");
  }
#endif
}

}  // namespace
}  // namespace plumb

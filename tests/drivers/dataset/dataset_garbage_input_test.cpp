// Property tests: arbitrary bytes in list, trajectory and camera files, and PNGs cut at every
// length, give a Status (ok or a message naming the file) and never crash or hang.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <random>

#include "tests/drivers/dataset_test_support.h"
#include "drivers/dataset/camera_presets.h"
#include "drivers/dataset/tum_dataset.h"
#include "drivers/dataset/tum_lists.h"
#include "drivers/trajectory/trajectory_io.h"

namespace plumb {
namespace {

// Mostly printable text with separators, digits and the odd control byte: closer to real
// corruption than uniform bytes, so parsers get past the first token.
std::string randomText(std::mt19937& rng, std::size_t length) {
  static const char kAlphabet[] = "0123456789.-+eE nan inf # \t,\n/rgbdepth.png\r\x01\xff";
  std::uniform_int_distribution<std::size_t> pick(0, sizeof(kAlphabet) - 2);
  std::string text;
  for (std::size_t i = 0; i < length; ++i) text += kAlphabet[pick(rng)];
  return text;
}

TEST(GarbageInput, TextReadersReturnAStatusNamingTheFile) {
  testing::TempDir dir;
  std::mt19937 rng(2024);
  std::uniform_int_distribution<std::size_t> length(0, 400);
  for (int trial = 0; trial < 300; ++trial) {
    const std::string path = dir.write("garbage.txt", randomText(rng, length(rng)));
    std::vector<StampedPose> poses;
    std::vector<TumListEntry> list;
    std::vector<TumFrameEntry> frames;
    PinholeCamera camera;
    for (const Status& st : {readTumTrajectory(path, &poses), readTumImageList(path, &list),
                             readTumAssociations(path, &frames), cameraFromSpec(path, &camera)}) {
      if (!st.ok()) {
        EXPECT_NE(st.message().find(path), std::string::npos) << st.message();
      }
    }
    // Whatever parsed must satisfy the documented guarantees.
    for (std::size_t i = 1; i < poses.size(); ++i) EXPECT_GT(poses[i].timestamp, poses[i - 1].timestamp);
    for (const StampedPose& p : poses) EXPECT_TRUE(p.T_world_cam.matrix().allFinite());
  }
}

TEST(GarbageInput, PngCutAtEveryLengthFailsOrLoadsTheExactImage) {
  testing::TempDir dir;
  cv::Mat depth(6, 8, CV_16UC1);
  cv::randu(depth, 0, 60000);
  std::vector<uchar> depth_png, colour_png;
  ASSERT_TRUE(cv::imencode(".png", depth, depth_png));
  ASSERT_TRUE(cv::imencode(".png", cv::Mat(6, 8, CV_8UC3, cv::Scalar(1, 2, 3)), colour_png));
  dir.write("seq/rgb.txt", "1.0 rgb/a.png\n");
  dir.write("seq/depth.txt", "1.0 depth/a.png\n");
  dir.write("seq/rgb/a.png", std::string(colour_png.begin(), colour_png.end()));
  dir.write("seq/depth/a.png", std::string(depth_png.begin(), depth_png.end()));
  PinholeCamera camera;
  camera.fx = camera.fy = 10;
  camera.width = 8;
  camera.height = 6;
  std::unique_ptr<TumDatasetSource> source;
  ASSERT_TRUE(TumDatasetSource::open(dir.file("seq"), camera, &source).ok());
  const std::string depth_path = dir.file("seq/depth/a.png");
  int loaded = 0;
  RgbdImage frame;
  for (std::size_t cut = 0; cut <= depth_png.size(); ++cut) {
    dir.write("seq/depth/a.png", std::string(depth_png.begin(), depth_png.begin() + cut));
    const Status st = source->load(0, frame);
    if (st.ok()) {
      // Accepted only if nothing of the pixels was lost (a cut in the trailing IEND chunk).
      ++loaded;
      EXPECT_EQ(cv::norm(frame.depth_raw, depth, cv::NORM_INF), 0.0) << "cut at " << cut;
    } else {
      EXPECT_NE(st.message().find(depth_path), std::string::npos) << st.message();
    }
  }
  EXPECT_GE(loaded, 1);  // the complete file
}

}  // namespace
}  // namespace plumb

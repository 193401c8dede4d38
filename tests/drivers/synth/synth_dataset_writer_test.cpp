// writeSynthDataset: TUM layout, byte-identical on a rerun, readable by plumb's own readers,
// clear errors for bad options and unwritable folders.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

#include <opencv2/imgcodecs.hpp>

#include "drivers/dataset/camera_file.h"
#include "drivers/synth/synthetic_scene.h"
#include "drivers/trajectory/trajectory_io.h"

namespace plumb {
namespace {

namespace fs = std::filesystem;

class SynthWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("plumb_synth_writer_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }
  fs::path root_;
};

std::string readAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<std::string> dataLines(const fs::path& path) {
  std::vector<std::string> lines;
  std::istringstream text(readAll(path));
  for (std::string line; std::getline(text, line);)
    if (!line.empty() && line[0] != '#') lines.push_back(line);
  return lines;
}

SynthOptions smallOptions() {
  SynthOptions options;
  options.preset = "low_texture";
  options.seed = 7;
  options.frames = 4;
  options.pixel_noise_sigma = 1.5;
  options.depth_noise = true;
  options.depth_edge_holes = true;
  return options;
}

TEST_F(SynthWriterTest, TwoRunsGiveByteIdenticalFolders) {
  ASSERT_TRUE(writeSynthDataset(smallOptions(), (root_ / "a").string()).ok());
  ASSERT_TRUE(writeSynthDataset(smallOptions(), (root_ / "b").string()).ok());
  int files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(root_ / "a")) {
    if (!entry.is_regular_file()) continue;
    const fs::path relative = fs::relative(entry.path(), root_ / "a");
    ASSERT_TRUE(fs::exists(root_ / "b" / relative)) << relative;
    EXPECT_EQ(readAll(entry.path()), readAll(root_ / "b" / relative)) << relative;
    ++files;
  }
  EXPECT_EQ(files, 2 * 4 + 5);  // 4 colour + 4 depth PNGs, 3 lists, ground truth, camera

  SynthOptions other = smallOptions();
  other.seed = 8;
  ASSERT_TRUE(writeSynthDataset(other, (root_ / "c").string()).ok());
  EXPECT_NE(readAll(root_ / "a" / "groundtruth.txt"), readAll(root_ / "c" / "groundtruth.txt"));
}

TEST_F(SynthWriterTest, FilesFollowTheTumLayout) {
  const SynthOptions options = smallOptions();
  const fs::path dir = root_ / "tum";
  ASSERT_TRUE(writeSynthDataset(options, dir.string()).ok());
  std::unique_ptr<SyntheticScene> scene;
  ASSERT_TRUE(SyntheticScene::create(options, &scene).ok());

  const auto rgb = dataLines(dir / "rgb.txt"), depth = dataLines(dir / "depth.txt");
  const auto associations = dataLines(dir / "associations.txt");
  ASSERT_EQ(rgb.size(), 4u);
  ASSERT_EQ(depth.size(), 4u);
  ASSERT_EQ(associations.size(), 4u);
  EXPECT_EQ(rgb[1], "1000.033333 rgb/1000.033333.png");
  EXPECT_EQ(depth[1], "1000.033333 depth/1000.033333.png");
  EXPECT_EQ(associations[3], "1000.100000 rgb/1000.100000.png 1000.100000 depth/1000.100000.png");

  std::vector<StampedPose> ground_truth;
  ASSERT_TRUE(readTumTrajectory((dir / "groundtruth.txt").string(), &ground_truth).ok());
  ASSERT_EQ(ground_truth.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(ground_truth[i].timestamp, scene->timestamp(i), 1e-6);
    EXPECT_TRUE(ground_truth[i].T_world_cam.isApprox(scene->T_world_cam(i), 1e-7));
  }
  PinholeCamera camera;
  ASSERT_TRUE(readCameraFile((dir / "camera.txt").string(), &camera).ok());
  EXPECT_EQ(camera.fx, synthCamera().fx);
  EXPECT_EQ(camera.cy, synthCamera().cy);
  EXPECT_EQ(camera.depth_factor, 5000.0);
  EXPECT_EQ(camera.width, 640);

  // The PNGs hold exactly what render() produces: 8-bit colour, 16-bit depth.
  RgbdImage frame;
  ASSERT_TRUE(scene->render(2, frame).ok());
  const cv::Mat bgr = cv::imread((dir / "rgb/1000.066667.png").string(), cv::IMREAD_UNCHANGED);
  const cv::Mat depth_raw = cv::imread((dir / "depth/1000.066667.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(bgr.type(), CV_8UC3);
  ASSERT_EQ(depth_raw.type(), CV_16UC1);
  EXPECT_EQ(cv::countNonZero(cv::Mat(bgr != frame.bgr).reshape(1)), 0);
  EXPECT_EQ(cv::countNonZero(depth_raw != frame.depth_raw), 0);
}

TEST_F(SynthWriterTest, BadOptionsAndUnwritableFoldersAreClearErrors) {
  SynthOptions options = smallOptions();
  options.preset = "glossy";
  Status status = writeSynthDataset(options, (root_ / "x").string());
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("unknown preset 'glossy'"), std::string::npos) << status.message();
  EXPECT_FALSE(fs::exists(root_ / "x")) << "nothing is written for bad options";

  options = smallOptions();
  options.frames = 0;
  status = writeSynthDataset(options, (root_ / "x").string());
  EXPECT_NE(status.message().find("frames must be positive"), std::string::npos) << status.message();

  // A folder below a regular file cannot be created (holds even when running as root).
  std::ofstream(root_ / "plain_file") << "not a folder";
  const fs::path impossible = root_ / "plain_file" / "out";
  status = writeSynthDataset(smallOptions(), impossible.string());
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find((root_ / "plain_file").string()), std::string::npos) << status.message();
}

}  // namespace
}  // namespace plumb

// The odometry cannot tell a recording from the folder it was made from: the same TUM frames
// replayed from the folder and from a .plumbrec give bit-identical poses.
#include <gtest/gtest.h>

#include <filesystem>

#include "drivers/open/open_source.h"
#include "drivers/recording/recording_writer.h"
#include "tests/drivers/device_test_util.h"
#include "tests/support/odometry_run.h"

namespace plumb {
namespace {

std::vector<Eigen::Isometry3d> track(FrameSource& source) {
  SystemOptions options;
  options.output_delay_frames = 0;
  test::RunSettings settings;
  settings.keep_outputs = true;
  const test::OdometryRun run = test::runOdometry(source, options, settings);
  EXPECT_TRUE(run.status.ok()) << run.status.message();
  std::vector<Eigen::Isometry3d> poses;
  for (const FrameOutput& out : run.outputs)
    poses.push_back(out.has_pose ? out.T_world_cam : Eigen::Isometry3d(Eigen::Matrix4d::Zero()));
  return poses;
}

TEST(RecordingOdometry, RecordingAndFolderGiveIdenticalPoses) {
  const std::string dataset = std::string(PLUMB_DATASETS_DIR) + "/tum_fr1_desk_first9";
  if (!std::filesystem::exists(dataset))
    GTEST_SKIP() << "shared TUM data not found at " << dataset;
  test::ScratchDir dir("rec_odometry");
  std::unique_ptr<FrameSource> folder;
  ASSERT_TRUE(openFrameSource(dataset, "", &folder).ok());
  {
    std::unique_ptr<RecordingWriter> writer;
    ASSERT_TRUE(RecordingWriter::open(dir.file("desk.plumbrec"), folder->camera(), {}, &writer).ok());
    RgbdImage frame;
    while (folder->next(frame) == SourceResult::kFrame) ASSERT_TRUE(writer->append(frame).ok());
    ASSERT_TRUE(writer->close().ok());
  }
  ASSERT_TRUE(openFrameSource(dataset, "", &folder).ok());
  std::unique_ptr<FrameSource> recording;
  ASSERT_TRUE(openFrameSource(dir.file("desk.plumbrec"), "", &recording).ok());
  const std::vector<Eigen::Isometry3d> from_folder = track(*folder);
  const std::vector<Eigen::Isometry3d> from_recording = track(*recording);
  ASSERT_EQ(from_folder.size(), 9u);
  ASSERT_EQ(from_recording.size(), from_folder.size());
  for (std::size_t i = 0; i < from_folder.size(); ++i)
    EXPECT_TRUE(from_folder[i].matrix() == from_recording[i].matrix()) << "frame " << i;
  EXPECT_FALSE(from_folder.back().matrix().isIdentity()) << "the camera moved: a real check";
}

}  // namespace
}  // namespace plumb

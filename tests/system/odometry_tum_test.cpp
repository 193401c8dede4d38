// Real data: TUM fr1/rpy (fast roll/pitch/yaw), the first 250 frames. Skipped without the data.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include "drivers/open/open_source.h"
#include "tests/support/odometry_run.h"

namespace plumb::test {
namespace {

TEST(OdometryTum, Fr1RpyHead250EveryFrameTracked) {
  const std::string dir = std::string(PLUMB_DATASETS_DIR) + "/tum_fr1_rpy_head250";
  struct stat info;
  if (stat(dir.c_str(), &info) != 0) GTEST_SKIP() << dir << " not found (needs ../shared/datasets)";
  std::unique_ptr<FrameSource> source;
  ASSERT_TRUE(openFrameSource(dir, "tum1", &source).ok());
  const OdometryRun run = runOdometry(*source, systemOptions(true));
  std::vector<StampedPose> gt;
  ASSERT_TRUE(readTumTrajectory(dir + "/groundtruth.txt", &gt).ok());
  EXPECT_EQ(run.trajectory.size(), 250u);
  EXPECT_EQ(run.stats.frames_lost, 0u);
  EXPECT_EQ(run.stats.segments, 1u);
  const double ate = ateRmse(gt, run.trajectory);
  RecordProperty("ate_rmse_m", std::to_string(ate));
  EXPECT_LT(ate, 0.035);  // acceptance target 0.020; see docs/ODOMETRY.md for the measured value
}

}  // namespace
}  // namespace plumb::test

// TUM trajectory files: round trip, lost-frame markers, deterministic bytes, bad lines.
#include "drivers/trajectory/trajectory_io.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include <cmath>

#include "tests/drivers/dataset_test_support.h"

namespace plumb {
namespace {

using testing::TempDir;

StampedPose pose(double t, double x, double y, double z, double angle_rad, Eigen::Vector3d axis) {
  StampedPose p;
  p.timestamp = t;
  p.T_world_cam = Eigen::Translation3d(x, y, z) * Eigen::AngleAxisd(angle_rad, axis.normalized());
  return p;
}

TEST(TrajectoryIo, WriteReadRoundTripWithLostFrames) {
  TempDir dir;
  std::vector<StampedPose> poses = {pose(1305031453.359684, 1.25, -0.5, 2, 0.3, {1, 2, 3}),
                                    pose(1305031453.391690, 1.26, -0.49, 2.01, 2.9, {0, 0, 1}),
                                    pose(1305031453.423683, 0, 0, 0, 0, {1, 0, 0})};
  StampedPose lost;
  lost.timestamp = 1305031453.391700;
  lost.valid = false;
  poses.insert(poses.begin() + 2, lost);
  StampedPose dropped;  // a real-time drop: never processed
  dropped.timestamp = 1305031453.423000;
  dropped.valid = false;
  dropped.dropped = true;
  poses.insert(poses.begin() + 3, dropped);
  const std::string path = dir.file("traj.txt");
  ASSERT_TRUE(writeTumTrajectory(path, poses).ok());
  const std::string text = testing::readWholeFile(path);
  EXPECT_NE(text.find("\n# 1305031453.391700 lost\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\n# 1305031453.423000 dropped\n"), std::string::npos) << text;

  std::vector<StampedPose> without_lost, with_lost;
  ASSERT_TRUE(readTumTrajectory(path, &without_lost).ok());
  TrajectoryReadOptions keep;
  keep.keep_lost_markers = true;
  ASSERT_TRUE(readTumTrajectory(path, &with_lost, keep).ok());
  ASSERT_EQ(without_lost.size(), 3u);
  ASSERT_EQ(with_lost.size(), 5u);
  EXPECT_FALSE(with_lost[2].valid);
  EXPECT_FALSE(with_lost[2].dropped);
  EXPECT_DOUBLE_EQ(with_lost[2].timestamp, lost.timestamp);
  EXPECT_FALSE(with_lost[3].valid);
  EXPECT_TRUE(with_lost[3].dropped);
  EXPECT_DOUBLE_EQ(with_lost[3].timestamp, dropped.timestamp);
  for (std::size_t i = 0; i < 3; ++i) {
    const StampedPose& expected = poses[i < 2 ? i : 4];
    EXPECT_NEAR(without_lost[i].timestamp, expected.timestamp, 1e-6);
    EXPECT_TRUE(without_lost[i].T_world_cam.isApprox(expected.T_world_cam, 1e-8)) << i;
  }
  // Writing what we read gives the same bytes: the format is deterministic.
  const std::string path2 = dir.file("traj2.txt");
  ASSERT_TRUE(writeTumTrajectory(path2, with_lost).ok());
  EXPECT_EQ(testing::readWholeFile(path2), text);
}

TEST(TrajectoryIo, LineFormatIsTumWithPositiveQw) {
  StampedPose p = pose(12.5, 1, 2, 3, M_PI / 2, {0, 0, 1});
  EXPECT_EQ(formatTumLine(p), "12.500000 1 2 3 0 0 0.707106781 0.707106781");
  // 270 degrees about z has a quaternion with qw < 0; the writer picks the qw >= 0 sign.
  p = pose(12.5, 1, 2, 3, 3 * M_PI / 2, {0, 0, 1});
  EXPECT_EQ(formatTumLine(p), "12.500000 1 2 3 0 0 -0.707106781 0.707106781");
  p.valid = false;
  EXPECT_EQ(formatTumLine(p), "# 12.500000 lost");
}

TEST(TrajectoryIo, AcceptsCommasTabsCommentsAndNormalisesNearUnitQuaternions) {
  TempDir dir;
  const std::string path = dir.write("t.txt",
                                     "# header\n"
                                     "1.0,0,0,0,0,0,0,1\n"
                                     "2.0\t1\t0\t0\t0\t0\t0.7071\t0.7071\n");
  std::vector<StampedPose> poses;
  TrajectoryReadReport report;
  const Status st = readTumTrajectory(path, &poses, {}, &report);
  ASSERT_TRUE(st.ok()) << st.message();
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_EQ(report.quaternions_normalised, 1);
  const Eigen::Matrix3d R = poses[1].T_world_cam.linear();
  EXPECT_NEAR((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 0, 1e-12);
}

TEST(TrajectoryIo, DuplicateTimestampKeepsTheLaterLineLikeTheBenchmark) {
  TempDir dir;
  const std::string path = dir.write("t.txt",
                                     "1.0 0 0 0 0 0 0 1\n"
                                     "2.0 5 0 0 0 0 0 1\n"
                                     "2.0 7 0 0 0 0 0 1\n"
                                     "3.0 9 0 0 0 0 0 1\n");
  std::vector<StampedPose> poses;
  TrajectoryReadReport report;
  ASSERT_TRUE(readTumTrajectory(path, &poses, {}, &report).ok());
  ASSERT_EQ(poses.size(), 3u);
  EXPECT_EQ(poses[1].T_world_cam.translation().x(), 7.0);
  EXPECT_EQ(report.duplicate_timestamps_replaced, 1);
}

void expectTrajectoryError(const std::string& content, const std::string& location,
                           const std::string& words) {
  TempDir dir;
  const std::string path = dir.write("traj.txt", content);
  std::vector<StampedPose> poses;
  const Status st = readTumTrajectory(path, &poses);
  ASSERT_FALSE(st.ok()) << content;
  EXPECT_NE(st.message().find(path + location), std::string::npos) << st.message();
  EXPECT_NE(st.message().find(words), std::string::npos) << st.message();
}

// Found by fuzz/trajectory_reader_fuzzer.cpp: the reader accepts any finite timestamp, but the
// writer's 256-byte line cut a %.6f timestamp above ~1e240 short, so the file it wrote did not
// read back. Every finite value must now print whole and read back.
TEST(TrajectoryIo, HugeFiniteValuesWriteWholeLinesThatReadBack) {
  TempDir dir;
  StampedPose big = pose(1e300, -1.5e308, 2.5e-308, 1e300, 0.4, {1, 1, 0});
  StampedPose lost;
  lost.timestamp = 1.7976931348623157e308;
  lost.valid = false;
  lost.dropped = true;
  const std::string line = formatTumLine(big);
  EXPECT_GT(line.size(), 300u);
  EXPECT_LT(line.size(), kTumLineCapacity);
  EXPECT_EQ(std::count(line.begin(), line.end(), ' '), 7) << line;  // all 8 fields
  const std::string path = dir.file("huge.txt");
  ASSERT_TRUE(writeTumTrajectory(path, {big, lost}).ok());
  std::vector<StampedPose> read;
  TrajectoryReadOptions options;
  options.keep_lost_markers = true;
  const Status status = readTumTrajectory(path, &read, options);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0].timestamp, 1e300);
  EXPECT_EQ(read[0].T_world_cam.translation().x(), -1.5e308);  // %.9g: 9 digits exact
  EXPECT_NEAR(read[0].T_world_cam.translation().y(), 2.5e-308, 1e-316);
  EXPECT_TRUE(read[0].T_world_cam.linear().isApprox(big.T_world_cam.linear(), 1e-8));
  EXPECT_FALSE(read[1].valid);
  EXPECT_TRUE(read[1].dropped);
  EXPECT_EQ(read[1].timestamp, 1.7976931348623157e308);
}

TEST(TrajectoryIo, BadLinesNameFileAndLine) {
  const std::string good = "# c\n1.0 0 0 0 0 0 0 1\n";
  expectTrajectoryError(good + "2.0 nan 0 0 0 0 0 1\n", ":3", "tx is not finite");
  expectTrajectoryError(good + "2.0 0 0 0 0 0 0 1 5\n", ":3", "got 9");
  expectTrajectoryError(good + "2.0 0 0 0 0 0 1\n", ":3", "got 7");
  expectTrajectoryError(good + "2.0 0 0 0 0 0 0 0\n", ":3", "zero quaternion");
  expectTrajectoryError(good + "2.0 0 0 0 0 0 0 2\n", ":3", "quaternion norm 2");
  expectTrajectoryError(good + "2.0 0 0 zero 0 0 0 1\n", ":3", "tz 'zero' is not a number");
  expectTrajectoryError(good + "0.5 0 0 0 0 0 0 1\n", ":3", "non-monotonic");
  expectTrajectoryError(good + "inf 0 0 0 0 0 0 1\n", ":3", "timestamp is not finite");
  expectTrajectoryError("# only comments\n\n", "", "no poses");
  expectTrajectoryError("", "", "no poses");
}

TEST(TrajectoryIo, MissingFileIsNamed) {
  std::vector<StampedPose> poses;
  const Status st = readTumTrajectory("/nonexistent/plumb/traj.txt", &poses);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("/nonexistent/plumb/traj.txt"), std::string::npos) << st.message();
}

TEST(TrajectoryIo, StreamingWriterMatchesBatchWriter) {
  TempDir dir;
  std::vector<StampedPose> poses = {pose(1, 0.1, 0.2, 0.3, 0.1, {0, 1, 0}),
                                    pose(2, 0.4, 0.5, 0.6, 0.2, {1, 1, 0})};
  ASSERT_TRUE(writeTumTrajectory(dir.file("a.txt"), poses).ok());
  {
    TumTrajectoryWriter writer;
    ASSERT_TRUE(writer.open(dir.file("b.txt")).ok());
    for (const StampedPose& p : poses) ASSERT_TRUE(writer.append(p).ok());
    ASSERT_TRUE(writer.close().ok());
  }
  EXPECT_EQ(testing::readWholeFile(dir.file("a.txt")), testing::readWholeFile(dir.file("b.txt")));
  {
    // A writer destroyed without close() (a crash, an error path) leaves no file that looks whole.
    TumTrajectoryWriter writer;
    ASSERT_TRUE(writer.open(dir.file("c.txt")).ok());
    for (const StampedPose& p : poses) ASSERT_TRUE(writer.append(p).ok());
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("c.txt")));
  TumTrajectoryWriter bad;
  const Status st = bad.open(dir.file("no/such/dir/t.txt"));
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("no/such/dir/t.txt"), std::string::npos);
}

}  // namespace
}  // namespace plumb

// `plumb run` refuses impossible options at start, with a message, before any output exists: an
// option is never silently changed into another meaning (issue: --line-samples 1 once meant "no
// lines" without a word).
#include <gtest/gtest.h>

#include <filesystem>

#include "pipeline/odometry/odometry_system.h"
#include "tests/support/plumb_cli.h"

namespace plumb::test {
namespace {

TEST(RunOptionsValidation, OneLineSampleIsRefusedByTheSystem) {
  SystemOptions options;
  setLineSamples(1, true, &options.odometry);
  const Status st = validate(options);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("at least two samples"), std::string::npos) << st.message();
  // And the system cannot be built with it.
  PinholeCamera camera;
  camera.fx = camera.fy = 500;
  camera.cx = 320;
  camera.cy = 240;
  std::unique_ptr<OdometrySystem> system;
  EXPECT_FALSE(OdometrySystem::create(camera, options, &system).ok());
  EXPECT_EQ(system, nullptr);
}

TEST(RunOptionsValidation, EveryOtherSampleCountIsAccepted) {
  for (int n : {0, 2, 3, 5, 10}) {
    SystemOptions options;
    setLineSamples(n, true, &options.odometry);
    EXPECT_TRUE(validate(options).ok()) << n << ": " << validate(options).message();
    EXPECT_EQ(options.odometry.tracker.use_lines, n > 0) << n;
    if (n >= 2) EXPECT_LE(options.odometry.extractor.min_line_inliers, n) << n;
  }
}

TEST(RunOptionsValidation, MinLineInliersAboveSamplesIsRefused) {
  SystemOptions options;
  options.odometry.extractor.line_samples = 3;
  options.odometry.extractor.min_line_inliers = 4;
  EXPECT_FALSE(validate(options).ok());
}

TEST(RunCli, OneLineSampleIsRefusedBeforeAnyOutput) {
  ScratchDir dir("plumb_run_cli");
  ASSERT_TRUE(dir.ok());
  const std::string out = dir.file("t.txt");
  const RunResult r = runPlumb("run --dataset synth:low_texture:1:20 --line-samples 1 --out '" + out + "'");
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("at least two samples"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(RunCli, TwoLineSamplesTrackWithLines) {
  ScratchDir dir("plumb_run_cli");
  ASSERT_TRUE(dir.ok());
  const std::string stats = dir.file("stats.json");
  const RunResult r = runPlumb("run --dataset synth:low_texture:1:20 --line-samples 2 --out '" + dir.file("t.txt") +
                               "' --stats '" + stats + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(stats);
  const std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // The options the run used are in the statistics: lines on, 2 samples, 2 inliers needed.
  EXPECT_NE(json.find("\"line_samples\": 2, \"lines\": true, \"min_line_inliers\": 2"), std::string::npos) << json;
  // Lines were really made into landmarks with 2 samples each.
  EXPECT_EQ(json.find("\"lines_created\": 0,"), std::string::npos) << json;
}

}  // namespace
}  // namespace plumb::test

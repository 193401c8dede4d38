// `plumb run` refuses impossible options at start, with a message, before any output exists: an
// option is never silently changed into another meaning (issue: --line-samples 1 once meant "no
// lines" without a word).
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>

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
    if (n >= 2) {
      EXPECT_LE(options.odometry.extractor.min_line_inliers, n) << n;
    }
  }
}

TEST(RunOptionsValidation, MinLineInliersAboveSamplesIsRefused) {
  SystemOptions options;
  options.odometry.extractor.line_samples = 3;
  options.odometry.extractor.min_line_inliers = 4;
  EXPECT_FALSE(validate(options).ok());
}

TEST(RunCli, StatsRecordEveryOptionOfTheCommandLine) {
  ScratchDir dir("plumb_run_options");
  ASSERT_TRUE(dir.ok());
  const std::string stats = dir.file("s.json");
  const RunResult r = runPlumb("run --dataset synth:textured:1:5 --discard-trajectory --output-delay 7 --no-loops "
                               "--stats '" + stats + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(stats);
  const std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t at = json.find("\"command_options\": {");
  ASSERT_NE(at, std::string::npos) << json;
  const std::string options = json.substr(at, json.find('}', at) - at);
  // Given values, defaults and switches alike: every flag of `plumb run --help`.
  for (const char* entry : {"\"dataset\": \"synth:textured:1:5\"", "\"output-delay\": 7", "\"no-loops\": true",
                            "\"line-samples\": 5", "\"mode\": \"deterministic\"", "\"out\": null", "\"slots\": 8",
                            "\"progress\": false", "\"skip-frames\": 0", "\"mlock\": false", "\"mavlink\": null"}) {
    EXPECT_NE(options.find(entry), std::string::npos) << entry << " in " << options;
  }
  const RunResult help = runPlumb("run --help");
  std::size_t flags = 0;
  for (std::size_t p = help.output.find("\n  --"); p != std::string::npos; p = help.output.find("\n  --", p + 1)) ++flags;
  std::size_t keys = 0;
  for (std::size_t p = options.find("\": "); p != std::string::npos; p = options.find("\": ", p + 1)) ++keys;
  EXPECT_EQ(keys, flags + 1) << options;  // + the "command_options" key itself
}

TEST(RunCli, ProgressLineHasFramesPerSecondAndEta) {
  ScratchDir dir("plumb_run_progress");
  ASSERT_TRUE(dir.ok());
  // Not a terminal here: off by default, a line every 100 frames when asked.
  const RunResult quiet = runPlumb("run --dataset synth:textured:1:100 --discard-trajectory --no-loops");
  ASSERT_EQ(quiet.exit_code, 0) << quiet.output;
  EXPECT_EQ(quiet.output.find("frames/s, ETA"), std::string::npos) << quiet.output;
  const RunResult r = runPlumb("run --dataset synth:textured:1:100 --discard-trajectory --no-loops --progress");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("frame 100/100 (100%), "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(" frames/s, ETA 0:00: "), std::string::npos) << r.output;
  EXPECT_EQ(runPlumb("run --dataset synth:textured:1:5 --discard-trajectory --progress --no-progress").exit_code, 2);
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

// --out-optimized: one line per frame like --out; without loop closing there is no graph, so the
// two files are the same bytes (docs/LOOP.md "Two trajectories").
TEST(RunCli, OutOptimizedHasEveryFrameAndEqualsOutWithoutLoops) {
  ScratchDir dir("plumb_run_cli");
  ASSERT_TRUE(dir.ok());
  const std::string a = dir.file("a.txt"), b = dir.file("b.txt");
  RunResult r = runPlumb("run --dataset synth:textured:1:40 --no-loops --out '" + a + "' --out-optimized '" + b + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream ia(a, std::ios::binary), ib(b, std::ios::binary);
  const std::string sa((std::istreambuf_iterator<char>(ia)), std::istreambuf_iterator<char>());
  const std::string sb((std::istreambuf_iterator<char>(ib)), std::istreambuf_iterator<char>());
  EXPECT_EQ(std::count(sa.begin(), sa.end(), '\n'), 41);  // header + 40 frames
  EXPECT_EQ(sa, sb);
  // With loop closing (no loop in 40 frames): still one line per frame, and the statistics say so.
  const std::string stats = dir.file("s.json");
  r = runPlumb("run --dataset synth:textured:1:40 --out '" + a + "' --out-optimized '" + b + "' --stats '" + stats + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream ib2(b, std::ios::binary), is(stats);
  const std::string sb2((std::istreambuf_iterator<char>(ib2)), std::istreambuf_iterator<char>());
  const std::string json((std::istreambuf_iterator<char>(is)), std::istreambuf_iterator<char>());
  EXPECT_EQ(std::count(sb2.begin(), sb2.end(), '\n'), 41);
  EXPECT_NE(json.find("\"loop_closing\": {\"enabled\": true"), std::string::npos) << json;
  EXPECT_NE(json.find("\"loops_found\": 0"), std::string::npos) << json;
}

}  // namespace
}  // namespace plumb::test

namespace plumb::test {
namespace {

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A small TUM-layout folder written by `plumb synth`, as a user's dataset.
class RunDataSafety : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(dir_.ok());
    dataset_ = dir_.file("ds");
    const RunResult r = runPlumb("synth --preset textured --frames 12 --out '" + dataset_ + "'");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    ASSERT_TRUE(std::filesystem::exists(dataset_ + "/groundtruth.txt"));
  }
  ScratchDir dir_{"plumb_run_safety"};
  std::string dataset_;
};

TEST_F(RunDataSafety, OutputEqualToGroundTruthIsRefusedAndTheGroundTruthSurvives) {
  const std::string gt = dataset_ + "/groundtruth.txt";
  const std::string before = readAll(gt);
  const RunResult r = runPlumb("run --dataset '" + dataset_ + "' --out '" + gt + "' --gt '" + gt + "'");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("refusing to overwrite"), std::string::npos) << r.output;
  EXPECT_EQ(readAll(gt), before);
}

TEST_F(RunDataSafety, OutputOverAFileOfTheInputFolderIsRefused) {
  for (const std::string name : {"rgb.txt", "depth.txt", "camera.txt"}) {
    const std::string victim = dataset_ + "/" + name;
    const std::string before = readAll(victim);
    ASSERT_FALSE(before.empty()) << name;
    for (const std::string flag : {"--out", "--stats", "--covariance", "--out-optimized"}) {
      std::string args = "run --dataset '" + dataset_ + "' " + flag + " '" + victim + "'";
      if (flag != "--out") args += " --out '" + dir_.file("t.txt") + "'";
      const RunResult r = runPlumb(args);
      EXPECT_EQ(r.exit_code, 2) << flag << " " << name << ": " << r.output;
      EXPECT_EQ(readAll(victim), before) << flag << " " << name;
    }
  }
}

TEST_F(RunDataSafety, BadOutputPathsAreRefusedBeforeAnyWork) {
  const std::string out = dir_.file("t.txt");
  for (const std::string& extra : {std::string("--stats /nonexistent/folder/s.json"),
                                  std::string("--profile /nonexistent/p.json"),
                                  "--covariance '" + dir_.file("") + "'"}) {
    const RunResult r = runPlumb("run --dataset '" + dataset_ + "' --out '" + out + "' " + extra);
    EXPECT_EQ(r.exit_code, 2) << extra << ": " << r.output;
    EXPECT_FALSE(std::filesystem::exists(out)) << extra << ": the run started before the paths were checked";
  }
}

TEST_F(RunDataSafety, MissingOutRepeatedFlagsAndNegativeCountsAreUsageErrors) {
  EXPECT_EQ(runPlumb("run --dataset '" + dataset_ + "'").exit_code, 2);
  EXPECT_EQ(runPlumb("run --dataset '" + dataset_ + "' --out a.txt --out b.txt").exit_code, 2);
  EXPECT_EQ(runPlumb("run --dataset '" + dataset_ + "' --out '" + dir_.file("t.txt") + "' --max-frames -3").exit_code,
            2);
  EXPECT_FALSE(std::filesystem::exists(dir_.file("t.txt")));
  const RunResult discard = runPlumb("run --dataset '" + dataset_ + "' --discard-trajectory --max-frames 3");
  EXPECT_EQ(discard.exit_code, 0) << discard.output;
}

TEST_F(RunDataSafety, NoPartialFileUnderTheOutputNameAndNoLeftovers) {
  const std::string out = dir_.file("t.txt");
  const RunResult r = runPlumb("run --dataset '" + dataset_ + "' --out '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // One line per frame plus the header, and no temporary file left beside it.
  const std::string text = readAll(out);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 13) << text;
  for (const auto& entry : std::filesystem::directory_iterator(dir_.file("")))
    EXPECT_EQ(entry.path().filename().string().find(".partial"), std::string::npos) << entry.path();
}

TEST(RunStop, SigintKeepsEveryComputedPoseAndSaysSo) {
  ScratchDir dir("plumb_run_stop");
  ASSERT_TRUE(dir.ok());
  const std::string out = dir.file("t.txt"), stats = dir.file("s.json");
  // Long enough never to finish within the timeout on any machine.
  const std::string command = "timeout --preserve-status -s INT 8 '" + kPlumbBinary +
                              "' run --dataset synth:textured:1:100000 --out '" + out + "' --stats '" + stats +
                              "' 2>&1";
  std::FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buffer[4096];
  std::size_t n;
  while ((n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) output.append(buffer, n);
  const int status = ::pclose(pipe);
  ASSERT_TRUE(WIFEXITED(status)) << output;
  EXPECT_EQ(WEXITSTATUS(status), 3) << output;
  const std::string text = readAll(out);
  const std::string json = readAll(stats);
  EXPECT_NE(json.find("\"stopped_by_signal\": true"), std::string::npos) << json;
  // Every processed frame has its line (held-back poses included), and the last line is whole.
  unsigned long long frames = 0;
  const std::size_t at = json.find("\"frames\": ");
  ASSERT_NE(at, std::string::npos) << json;
  ASSERT_EQ(std::sscanf(json.c_str() + at, "\"frames\": %llu", &frames), 1);
  // (On a slow machine, e.g. under ASan, the signal may come while the scene is still being built:
  // then the run ends before its first frame, as cleanly, and replaces no trajectory file.)
  if (frames == 0) {
    EXPECT_FALSE(std::filesystem::exists(out)) << output;
    return;
  }
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), long(frames) + 1) << output;
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n');
}

}  // namespace
}  // namespace plumb::test

namespace plumb::test {
namespace {

TEST(OtherCommandsDataSafety, RecordRefusesToWriteOverItsSource) {
  ScratchDir dir("plumb_record_safety");
  ASSERT_TRUE(dir.ok());
  const std::string rec = dir.file("x.plumbrec");
  ASSERT_EQ(runPlumb("record --source synth:textured:1:5 --out '" + rec + "'").exit_code, 0);
  const std::string before = readAll(rec);
  ASSERT_GT(before.size(), 1000u);
  const RunResult r = runPlumb("record --source '" + rec + "' --out '" + rec + "'");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(readAll(rec), before);
}

TEST(OtherCommandsDataSafety, SynthAndConvertRefuseToWriteOverADataset) {
  ScratchDir dir("plumb_synth_safety");
  ASSERT_TRUE(dir.ok());
  const std::string ds = dir.file("ds");
  ASSERT_EQ(runPlumb("synth --preset textured --frames 4 --out '" + ds + "'").exit_code, 0);
  const std::string gt_before = readAll(ds + "/groundtruth.txt");
  const RunResult again = runPlumb("synth --preset low_texture --frames 4 --out '" + ds + "'");
  EXPECT_EQ(again.exit_code, 2) << again.output;
  EXPECT_EQ(readAll(ds + "/groundtruth.txt"), gt_before);
  const std::string rec = dir.file("ds.plumbrec");
  ASSERT_EQ(runPlumb("convert '" + ds + "' '" + rec + "'").exit_code, 0);
  const RunResult back = runPlumb("convert '" + rec + "' '" + ds + "'");
  EXPECT_EQ(back.exit_code, 2) << back.output;
  EXPECT_EQ(readAll(ds + "/groundtruth.txt"), gt_before);
}

}  // namespace
}  // namespace plumb::test

// `plumb run --mode ...`: the odometry driven through the runtime's staged pipeline (capture ->
// extract -> odometry, tools/staged_run.h) against the single-threaded loop, through the built tool.
// Lock-step (deterministic) must write the very same trajectory bytes; the threaded fast mode must
// account for every frame, in order. A short synthetic sequence keeps the test to a few seconds.

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/support/plumb_cli.h"

namespace {

using plumb::test::runPlumb;
using plumb::test::RunResult;

namespace fs = std::filesystem;

const std::string kPlumb = plumb::test::kPlumbBinary;
constexpr int kFrames = 60;
const std::string kDataset = "synth:low_texture:1:" + std::to_string(kFrames);

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Timestamps of the per-frame lines of a trajectory file, in file order: pose lines
// `t tx ty tz qx qy qz qw` and lost frames `# t lost`; other comment lines are headers.
std::vector<std::string> frameTimestamps(const std::string& bytes) {
  std::vector<std::string> stamps;
  std::istringstream lines(bytes);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::string first, second, third;
    words >> first >> second >> third;
    if (first != "#") {
      if (!first.empty()) stamps.push_back(first);
    } else if (third == "lost") {
      stamps.push_back(second);
    }
  }
  return stamps;
}

class StagedRun : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(dir_.ok()) << "no scratch folder";
    ASSERT_TRUE(fs::exists(kPlumb)) << kPlumb << " not built";
  }
  // Runs `plumb run` on the synthetic sequence with `extra` options; returns the trajectory bytes.
  std::string run(const std::string& name, const std::string& extra, RunResult* result = nullptr) {
    const std::string out = dir_.file(name);
    const RunResult r = runPlumb("run --dataset " + kDataset + " --out '" + out + "' " + extra);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    if (result) *result = r;
    return readBytes(out);
  }
  plumb::test::ScratchDir dir_{"plumb_staged"};
};

TEST_F(StagedRun, DeterministicModeWritesTheSingleThreadedBytes) {
  const std::string single = run("single.txt", "");
  RunResult staged_result;
  const std::string staged = run("deterministic.txt", "--mode deterministic", &staged_result);
  ASSERT_EQ(frameTimestamps(single).size(), std::size_t(kFrames)) << single;
  EXPECT_EQ(staged, single);
  EXPECT_NE(staged_result.output.find("deterministic:"), std::string::npos) << staged_result.output;
}

TEST_F(StagedRun, FastModeAccountsForEveryFrameInOrder) {
  const std::string single = run("single.txt", "");
  const std::string fast = run("fast.txt", "--mode fast --slots 3");
  const std::vector<std::string> single_stamps = frameTimestamps(single);
  ASSERT_EQ(single_stamps.size(), std::size_t(kFrames));
  EXPECT_EQ(frameTimestamps(fast), single_stamps);
  EXPECT_EQ(std::count(fast.begin(), fast.end(), '\n'), std::count(single.begin(), single.end(), '\n'));
}

TEST_F(StagedRun, ProfileWritesATraceAndCountAllocationsReports) {
  RunResult result;
  const std::string trace = dir_.file("trace.json");
  run("profiled.txt", "--mode fast --count-allocations --profile '" + trace + "'", &result);
  const std::string json = readBytes(trace);
  EXPECT_NE(json.find("traceEvents"), std::string::npos) << "trace file: " << json.substr(0, 200);
  EXPECT_NE(json.find("extract"), std::string::npos);
  EXPECT_NE(result.output.find("allocations after warm-up:"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("p99"), std::string::npos) << "no latency table:\n" << result.output;
}

TEST_F(StagedRun, ImpossibleScheduleValuesAreRefusedBeforeAnyWork) {
  for (const std::string extra : {"--slots 0", "--slots 65", "--rt-priority 100", "--mode quick"}) {
    const std::string out = dir_.file("refused.txt");
    const RunResult r = runPlumb("run --dataset " + kDataset + " --out '" + out + "' " + extra);
    EXPECT_NE(r.exit_code, 0) << extra;
    EXPECT_FALSE(fs::exists(out)) << extra << ": an output was written before the options were checked";
  }
  const RunResult bad = runPlumb("run --dataset " + kDataset + " --out '" + dir_.file("x.txt") + "' --mode quick");
  EXPECT_NE(bad.output.find("quick"), std::string::npos) << bad.output;
}

}  // namespace

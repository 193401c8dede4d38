// Issue 6: after warm-up the threaded pipeline allocates nothing per frame. Frames go through
// `plumb run --mode fast --count-allocations` (capture -> extract -> odometry on their own
// threads, trajectory written to a file); the tool counts every thread's operator new calls from
// frame 30 to the last frame and prints them. The assertion is on that process-wide count, so an
// allocation anywhere on the per-frame path (decoding, pyramid, tracking, mapping, trajectory
// writing) fails it.
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "tests/support/plumb_cli.h"

namespace {

using plumb::test::RunResult;
using plumb::test::runPlumb;
using plumb::test::ScratchDir;

// Reads "allocations after warm-up: <count> over <frames> frames (<per frame> per frame)" from the
// tool's output and checks that at least min_frames were counted and none of them allocated.
void expectNoAllocationsAfterWarmup(const std::string& output, unsigned long long min_frames) {
  const std::string key = "allocations after warm-up: ";
  const std::size_t at = output.find(key);
  ASSERT_NE(at, std::string::npos) << output;
  unsigned long long allocations = 0, frames = 0;
  ASSERT_EQ(std::sscanf(output.c_str() + at + key.size(), "%llu over %llu frames", &allocations, &frames), 2)
      << output;
  EXPECT_GE(frames, min_frames) << output;
  EXPECT_EQ(allocations, 0u) << output;
}

TEST(SteadyStateAllocations, ThreadedSyntheticRunAllocatesNothingPerFrameAfterFrame30) {
  const ScratchDir dir("plumb_alloc");
  ASSERT_TRUE(dir.ok());
  const RunResult r = runPlumb("run --dataset synth:low_texture:1:200 --out '" + dir.file("trajectory.txt") +
                               "' --mode fast --count-allocations");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // Frames 30..199, less the last few still in flight when the input ended (teardown excluded).
  expectNoAllocationsAfterWarmup(r.output, 150);
}

// The same for a replay of a TUM folder (the images read from files, per frame): the reader reuses
// its file buffer and its opener's path, so decoding allocates nothing either. The folder is a
// synthetic scene written by `plumb synth`, under a path longer than any short-string buffer.
TEST(SteadyStateAllocations, ThreadedTumFolderReplayAllocatesNothingPerFrameAfterFrame30) {
  const ScratchDir dir("plumb_alloc_tum_replay");
  ASSERT_TRUE(dir.ok());
  const std::string folder = dir.file("scene");
  const RunResult synth = runPlumb("synth --preset low_texture --seed 1 --frames 120 --out '" + folder + "'");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const RunResult r = runPlumb("run --dataset '" + folder + "' --out '" + dir.file("trajectory.txt") +
                               "' --mode fast --count-allocations");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  expectNoAllocationsAfterWarmup(r.output, 80);
}

}  // namespace

// Issue 6: after warm-up the threaded pipeline allocates nothing per frame. 200 synthetic frames go
// through `plumb run --mode fast --count-allocations` (capture -> extract -> odometry on their own
// threads, trajectory written to a file and kept for the ATE); the tool counts every thread's
// operator new calls from frame 30 to the last frame and prints them. The assertion is on that
// process-wide count, so an allocation anywhere on the per-frame path (pyramid, tracking, mapping,
// trajectory writing) fails it.
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace {

namespace fs = std::filesystem;

const std::string kPlumb = PLUMB_BINARY_DIR "/bin/plumb";

// Runs plumb with stdout and stderr captured; exit code -1 when it did not exit normally.
int runPlumb(const std::string& arguments, std::string* output) {
  const std::string command = "'" + kPlumb + "' " + arguments + " 2>&1";
  std::FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return -1;
  char buffer[4096];
  std::size_t n;
  while ((n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) output->append(buffer, n);
  const int status = ::pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

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
  std::string dir_pattern = (fs::temp_directory_path() / "plumb_alloc_XXXXXX").string();
  ASSERT_NE(::mkdtemp(dir_pattern.data()), nullptr);
  const std::string trajectory = dir_pattern + "/trajectory.txt";
  std::string output;
  const int exit_code =
      runPlumb("run --dataset synth:low_texture:1:200 --out '" + trajectory + "' --mode fast --count-allocations",
               &output);
  std::error_code ignored;
  fs::remove_all(dir_pattern, ignored);
  ASSERT_EQ(exit_code, 0) << output;
  // Frames 30..199, less the last few still in flight when the input ended (teardown excluded).
  expectNoAllocationsAfterWarmup(output, 150);
}

// The same for a replay of a TUM folder (the images read from files, per frame): the reader reuses
// its file buffer and its opener's path, so decoding allocates nothing either. The folder is a
// synthetic scene written by `plumb synth`, under a path longer than any short-string buffer.
TEST(SteadyStateAllocations, ThreadedTumFolderReplayAllocatesNothingPerFrameAfterFrame30) {
  std::string dir_pattern = (fs::temp_directory_path() / "plumb_alloc_tum_replay_XXXXXX").string();
  ASSERT_NE(::mkdtemp(dir_pattern.data()), nullptr);
  const std::string folder = dir_pattern + "/scene", trajectory = dir_pattern + "/trajectory.txt";
  std::string output;
  ASSERT_EQ(runPlumb("synth --preset low_texture --seed 1 --frames 120 --out '" + folder + "'", &output), 0) << output;
  output.clear();
  const int exit_code =
      runPlumb("run --dataset '" + folder + "' --out '" + trajectory + "' --mode fast --count-allocations", &output);
  std::error_code ignored;
  fs::remove_all(dir_pattern, ignored);
  ASSERT_EQ(exit_code, 0) << output;
  expectNoAllocationsAfterWarmup(output, 80);
}

}  // namespace

// `plumb synth` from the command line: the same options give a byte-identical folder, another seed
// gives other bytes, and bad options exit non-zero with a message that says what is wrong.
// Short runs keep the test fast; the 300-frame acceptance run is the same code path.

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "tests/support/plumb_cli.h"

namespace {

using plumb::test::runPlumb;
using plumb::test::RunResult;

namespace fs = std::filesystem;

constexpr int kFrames = 20;  // keeps each run short; determinism does not depend on the count

// Every regular file under `root`, keyed by its path relative to `root`, with its bytes.
std::map<std::string, std::string> readTree(const std::string& root) {
  std::map<std::string, std::string> files;
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(root)) {
    if (!entry.is_regular_file()) continue;
    std::ifstream in(entry.path(), std::ios::binary);
    files[fs::relative(entry.path(), root).string()] =
        std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  return files;
}

std::string synthArguments(const std::string& preset, int seed, int frames, const std::string& out) {
  return "synth --preset " + preset + " --seed " + std::to_string(seed) + " --frames " +
         std::to_string(frames) + " --out " + out;
}

TEST(SynthCli, SameSeedGivesByteIdenticalFolders) {
  plumb::test::ScratchDir dir{"plumb_synth"};
  const std::string first = dir.file("first");
  const std::string second = dir.file("second");
  RunResult r = runPlumb(synthArguments("low_texture", 7, kFrames, first));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = runPlumb(synthArguments("low_texture", 7, kFrames, second));
  ASSERT_EQ(r.exit_code, 0) << r.output;

  const std::map<std::string, std::string> first_files = readTree(first);
  const std::map<std::string, std::string> second_files = readTree(second);
  // One colour and one depth image per frame, plus the text files of the TUM layout.
  int rgb_images = 0;
  int depth_images = 0;
  for (const auto& [name, bytes] : first_files) {
    if (name.rfind("rgb/", 0) == 0) ++rgb_images;
    if (name.rfind("depth/", 0) == 0) ++depth_images;
    EXPECT_FALSE(bytes.empty()) << name << " is empty";
  }
  EXPECT_EQ(rgb_images, kFrames);
  EXPECT_EQ(depth_images, kFrames);
  for (const char* text : {"rgb.txt", "depth.txt", "associations.txt", "groundtruth.txt", "camera.txt"})
    EXPECT_EQ(first_files.count(text), 1u) << text << " missing from " << first;

  ASSERT_EQ(first_files.size(), second_files.size());
  for (const auto& [name, bytes] : first_files) {
    const auto other = second_files.find(name);
    ASSERT_NE(other, second_files.end()) << name << " only in the first run";
    EXPECT_TRUE(bytes == other->second) << name << " differs between two runs with the same seed";
  }
}

TEST(SynthCli, DifferentSeedGivesDifferentBytes) {
  plumb::test::ScratchDir dir{"plumb_synth"};
  const std::string seed7 = dir.file("seed7");
  const std::string seed8 = dir.file("seed8");
  constexpr int kFewFrames = 3;
  RunResult r = runPlumb(synthArguments("low_texture", 7, kFewFrames, seed7));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = runPlumb(synthArguments("low_texture", 8, kFewFrames, seed8));
  ASSERT_EQ(r.exit_code, 0) << r.output;

  const std::map<std::string, std::string> files7 = readTree(seed7);
  const std::map<std::string, std::string> files8 = readTree(seed8);
  ASSERT_EQ(files7.size(), files8.size());  // the layout does not depend on the seed
  int differing_images = 0;
  for (const auto& [name, bytes] : files7) {
    const auto other = files8.find(name);
    ASSERT_NE(other, files8.end()) << name << " missing for seed 8";
    const bool is_image = name.rfind("rgb/", 0) == 0 || name.rfind("depth/", 0) == 0;
    if (is_image && bytes != other->second) ++differing_images;
  }
  // The seed moves the room layout and the textures, so every image changes.
  EXPECT_EQ(differing_images, 2 * kFewFrames);
  EXPECT_NE(files7.at("groundtruth.txt"), files8.at("groundtruth.txt"));
}

TEST(SynthCli, UnknownPresetExitsNonZeroNamingIt) {
  plumb::test::ScratchDir dir{"plumb_synth"};
  const RunResult r = runPlumb(synthArguments("marble_hall", 7, 2, dir.file("out")));
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("unknown preset 'marble_hall'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("low_texture"), std::string::npos) << "message should list the presets: " << r.output;
  EXPECT_FALSE(fs::exists(dir.file("out/rgb.txt"))) << "a failed run wrote a dataset";
}

TEST(SynthCli, ZeroOrMalformedFramesExitNonZero) {
  plumb::test::ScratchDir dir{"plumb_synth"};
  RunResult r = runPlumb(synthArguments("textured", 7, 0, dir.file("out")));
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("frames must be positive"), std::string::npos) << r.output;

  r = runPlumb("synth --frames ten --out " + dir.file("out"));
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("--frames 'ten' is not a number"), std::string::npos) << r.output;
}

TEST(SynthCli, UsageErrorsExitWithTwo) {
  EXPECT_EQ(runPlumb("synth").exit_code, 2);                 // no --out
  EXPECT_EQ(runPlumb("synth --out x --bogus").exit_code, 2);  // unknown option
  EXPECT_EQ(runPlumb("synth --help").exit_code, 0);
}

}  // namespace

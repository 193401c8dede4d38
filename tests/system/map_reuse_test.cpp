// Map reuse through `plumb run --save-map / --load-map` (docs/LOOP.md "Map files"): a second run
// relocalizes into the first run's map within its first frames and continues in that map's world
// frame; broken or foreign maps are refused with a message, never a crash.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>
#include <vector>

#include "drivers/mapfile/map_file.h"
#include "drivers/synth/synth_spec.h"
#include "drivers/trajectory/evaluate.h"
#include "drivers/trajectory/trajectory_io.h"
#include "pipeline/loop/saved_map_codec.h"
#include "tests/support/plumb_cli.h"

namespace plumb::test {
namespace {

// The frame index `plumb run --load-map` printed as "relocalized at frame N" (-1: none).
int relocalizedFrame(const std::string& output) {
  std::smatch m;
  if (!std::regex_search(output, m, std::regex("relocalized at frame ([0-9]+)"))) return -1;
  return std::stoi(m[1]);
}

std::vector<uint8_t> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void writeBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

std::vector<StampedPose> concatenated(const std::string& a, const std::string& b) {
  std::vector<StampedPose> first, second;
  EXPECT_TRUE(readTumTrajectory(a, &first).ok());
  EXPECT_TRUE(readTumTrajectory(b, &second).ok());
  first.insert(first.end(), second.begin(), second.end());
  return first;
}

double ateOf(const std::vector<StampedPose>& gt, const std::vector<StampedPose>& estimate) {
  AteResult r;
  const Status st = evaluateAte(gt, estimate, AteOptions{}, &r);
  EXPECT_TRUE(st.ok()) << st.message();
  return r.translation_m.rmse;
}

TEST(MapReuse, SyntheticSecondHalfRelocalizesIntoTheFirstHalfsMap) {
  ScratchDir dir("plumb_map_reuse");
  ASSERT_TRUE(dir.ok());
  const std::string spec = "synth:textured:1:300";
  RunResult first = runPlumb("run --dataset " + spec + " --max-frames 150 --out " + dir.file("a.txt") +
                             " --save-map " + dir.file("m.map"));
  ASSERT_EQ(first.exit_code, 0) << first.output;
  EXPECT_NE(first.output.find("map saved:"), std::string::npos) << first.output;
  RunResult second = runPlumb("run --dataset " + spec + " --skip-frames 150 --load-map " + dir.file("m.map") +
                              " --out " + dir.file("b.txt") + " --save-map " + dir.file("m2.map"));
  ASSERT_EQ(second.exit_code, 0) << second.output;
  const int relocalized = relocalizedFrame(second.output);
  RecordProperty("relocalized_frame", relocalized);
  ASSERT_GE(relocalized, 0) << second.output;
  EXPECT_LE(relocalized, 9) << second.output;

  // Ground truth in the saved map's frame: run 1 started its map at frame 0 with the identity.
  std::unique_ptr<SyntheticSource> synth;
  ASSERT_TRUE(openSynthSpec(spec, false, &synth).ok());
  const std::vector<StampedPose> gt = syntheticGroundTruth(synth->scene(), 300);
  const Eigen::Isometry3d T_map_gtworld = gt[0].T_world_cam.inverse();
  std::vector<StampedPose> b;
  ASSERT_TRUE(readTumTrajectory(dir.file("b.txt"), &b).ok());
  ASSERT_EQ(b.size(), 150u);  // one line per input frame, those before relocalization included
  double max_translation = 0, max_rotation_deg = 0;
  int with_pose = 0;
  for (std::size_t i = 0; i < b.size(); ++i) {
    EXPECT_NEAR(b[i].timestamp, gt[150 + i].timestamp, 1e-6);
    if (!b[i].valid) {
      EXPECT_LT(int(i), relocalized) << "no pose after relocalization at frame " << i;
      continue;
    }
    ++with_pose;
    const Eigen::Isometry3d truth = T_map_gtworld * gt[150 + i].T_world_cam;
    const Eigen::Isometry3d error = truth.inverse() * b[i].T_world_cam;
    max_translation = std::max(max_translation, error.translation().norm());
    max_rotation_deg = std::max(max_rotation_deg, Eigen::AngleAxisd(error.linear()).angle() * 180 / M_PI);
  }
  RecordProperty("max_translation_error_m", std::to_string(max_translation));
  RecordProperty("max_rotation_error_deg", std::to_string(max_rotation_deg));
  std::printf("synthetic map reuse: relocalized at frame %d, %d poses, max error %.4f m, %.3f deg (saved map frame, "
              "no alignment)\n",
              relocalized, with_pose, max_translation, max_rotation_deg);
  EXPECT_EQ(with_pose, 150 - relocalized);
  EXPECT_LT(max_translation, 0.03);
  EXPECT_LT(max_rotation_deg, 1.0);

  // The second run's map holds the loaded keyframes and its own.
  std::vector<MapFileSection> a_sections, b_sections;
  ASSERT_TRUE(readMapFile(dir.file("m.map"), loop::kSavedMapFormatVersion, MapFileLimits{}, &a_sections).ok());
  ASSERT_TRUE(readMapFile(dir.file("m2.map"), loop::kSavedMapFormatVersion, MapFileLimits{}, &b_sections).ok());
  EXPECT_GT(b_sections[1].bytes.size(), a_sections[1].bytes.size());
}

// A place the map never saw: every frame is tried against the map, none gets a pose (one `lost`
// line per input frame), and no map of its own is started in an unrelated frame.
TEST(MapReuse, AnUnmappedPlaceStaysWithoutPosesAndStartsNoMap) {
  ScratchDir dir("plumb_map_elsewhere");
  ASSERT_TRUE(dir.ok());
  RunResult made = runPlumb("run --dataset synth:textured:1:60 --discard-trajectory --save-map " + dir.file("m.map"));
  ASSERT_EQ(made.exit_code, 0) << made.output;
  RunResult elsewhere = runPlumb("run --dataset synth:textured:2:30 --load-map " + dir.file("m.map") + " --out " +
                                 dir.file("t.txt") + " --stats " + dir.file("s.json"));
  ASSERT_EQ(elsewhere.exit_code, 0) << elsewhere.output;
  EXPECT_NE(elsewhere.output.find("never relocalized"), std::string::npos) << elsewhere.output;
  EXPECT_NE(elsewhere.output.find("map segments 0"), std::string::npos) << elsewhere.output;
  // (readTumTrajectory refuses a trajectory without a single pose, so the lines are counted here.)
  std::ifstream trajectory(dir.file("t.txt"));
  int lost = 0, poses = 0;
  for (std::string line; std::getline(trajectory, line);) {
    if (std::regex_match(line, std::regex("# [0-9]+\\.[0-9]{6} lost"))) {
      ++lost;
    } else if (!line.empty() && line[0] != '#') {
      ++poses;
    }
  }
  EXPECT_EQ(lost, 30);
  EXPECT_EQ(poses, 0);
  std::ifstream json(dir.file("s.json"));
  const std::string stats((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
  EXPECT_NE(stats.find("\"relocalization_attempts\": 30"), std::string::npos);
  EXPECT_NE(stats.find("\"relocalized_frame\": -1"), std::string::npos);
}

TEST(MapReuse, BrokenOrForeignMapsAreRefusedBeforeAnyWork) {
  ScratchDir dir("plumb_map_refuse");
  ASSERT_TRUE(dir.ok());
  const std::string spec = "synth:textured:1:40";
  RunResult made = runPlumb("run --dataset " + spec + " --discard-trajectory --save-map " + dir.file("m.map"));
  ASSERT_EQ(made.exit_code, 0) << made.output;
  const std::vector<uint8_t> good = readBytes(dir.file("m.map"));
  ASSERT_GT(good.size(), 1000u);
  auto load = [&](const std::vector<uint8_t>& bytes) {
    writeBytes(dir.file("x.map"), bytes);
    return runPlumb("run --dataset " + spec + " --discard-trajectory --load-map " + dir.file("x.map"));
  };
  // Truncated, a flipped byte, a future version, a foreign file.
  RunResult r = load(std::vector<uint8_t>(good.begin(), good.begin() + long(good.size() / 2)));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("truncated"), std::string::npos) << r.output;
  std::vector<uint8_t> flipped = good;
  flipped[good.size() / 3] ^= 0x10;
  r = load(flipped);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("CRC mismatch"), std::string::npos) << r.output;
  r = load(std::vector<uint8_t>{'n', 'o', 't', ' ', 'a', ' ', 'm', 'a', 'p'});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("not a plumb map"), std::string::npos) << r.output;

  // Another camera: the same map with fx changed (a valid file otherwise).
  std::vector<MapFileSection> sections;
  ASSERT_TRUE(parseMapFile(good.data(), good.size(), loop::kSavedMapFormatVersion, MapFileLimits{}, &sections).ok());
  std::vector<loop::MapSectionBytes> codec_sections;
  for (auto& s : sections) codec_sections.push_back(loop::MapSectionBytes{s.tag, s.bytes});
  loop::SavedMap map;
  ASSERT_TRUE(loop::decodeSavedMap(codec_sections, loop::SavedMapLimits{}, &map).ok());
  map.camera.fx *= 1.1;
  loop::encodeSavedMap(map, &codec_sections);
  sections.clear();
  for (auto& s : codec_sections) sections.push_back(MapFileSection{s.tag, s.bytes});
  r = load(encodeMapFile(loop::kSavedMapFormatVersion, sections));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("another camera: fx"), std::string::npos) << r.output;

  // The map as its own output, --save-map without loop closing, a negative --skip-frames.
  r = runPlumb("run --dataset " + spec + " --discard-trajectory --load-map " + dir.file("m.map") + " --save-map " +
               dir.file("m.map"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--save-map"), std::string::npos) << r.output;
  EXPECT_EQ(readBytes(dir.file("m.map")), good);
  r = runPlumb("run --dataset " + spec + " --discard-trajectory --no-loops --save-map " + dir.file("n.map"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("needs loop closing"), std::string::npos) << r.output;
  r = runPlumb("run --dataset " + spec + " --discard-trajectory --skip-frames -3");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--skip-frames"), std::string::npos) << r.output;
}

// A TUM folder holding associations [first, first + count) of `data`'s associations.txt, its images
// reached through links to `data`'s rgb/ and depth/ (nothing copied). False when it cannot be made.
bool makeSplitFolder(const std::string& data, const std::string& folder, int first, int count) {
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  const std::string source = std::filesystem::absolute(data, error).string();
  for (const char* images : {"rgb", "depth"}) {
    std::filesystem::create_directory_symlink(source + "/" + images, folder + "/" + images, error);
    if (error) return false;
  }
  std::ifstream in(data + "/associations.txt");
  std::ofstream out(folder + "/associations.txt");
  std::string line;
  int index = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (index >= first && index < first + count) out << line << "\n";
    ++index;
  }
  return bool(out) && index >= first + count;
}

// The acceptance on real data, the protocol: head250 split into two folders (the first 125
// associated pairs, then the last 125), run 1 on the first with --save-map, run 2 on the second with
// --load-map; the two trajectories joined and aligned with one rigid transform. The loaded run is
// byte-identical to --skip-frames 125 on the whole folder (the split changes nothing: timestamps,
// association, first frame and relocalization are the same), so the two ways of measuring it differ
// only by which of run 1's trajectories is joined (docs/LOOP.md "Map files").
TEST(MapReuse, TumHead250SecondHalfInTheFirstHalfsMap) {
  const std::string data = std::string(PLUMB_DATASETS_DIR) + "/tum_fr1_rpy_head250";
  struct stat info;
  if (stat(data.c_str(), &info) != 0) GTEST_SKIP() << data << " not found (needs ../shared/datasets)";
  ScratchDir dir("plumb_map_tum");
  ASSERT_TRUE(dir.ok());
  ASSERT_TRUE(makeSplitFolder(data, dir.file("first"), 0, 125));
  ASSERT_TRUE(makeSplitFolder(data, dir.file("second"), 125, 125));
  RunResult full = runPlumb("run --dataset " + data + " --camera tum1 --out " + dir.file("full.txt") +
                            " --out-optimized " + dir.file("full_opt.txt"));
  ASSERT_EQ(full.exit_code, 0) << full.output;
  RunResult first = runPlumb("run --dataset " + dir.file("first") + " --camera tum1 --out " + dir.file("a.txt") +
                             " --out-optimized " + dir.file("a_opt.txt") + " --save-map " + dir.file("m.map"));
  ASSERT_EQ(first.exit_code, 0) << first.output;
  RunResult second = runPlumb("run --dataset " + dir.file("second") + " --camera tum1 --load-map " +
                              dir.file("m.map") + " --out " + dir.file("b.txt") + " --out-optimized " +
                              dir.file("b_opt.txt") + " --stats " + dir.file("b.json"));
  ASSERT_EQ(second.exit_code, 0) << second.output;
  const int relocalized = relocalizedFrame(second.output);
  ASSERT_GE(relocalized, 0) << second.output;
  EXPECT_LE(relocalized, 9);
  RunResult skipped = runPlumb("run --dataset " + data + " --camera tum1 --skip-frames 125 --load-map " +
                               dir.file("m.map") + " --out " + dir.file("b_skip.txt"));
  ASSERT_EQ(skipped.exit_code, 0) << skipped.output;
  EXPECT_EQ(readBytes(dir.file("b.txt")), readBytes(dir.file("b_skip.txt")))
      << "the second folder and --skip-frames 125 on the whole folder gave different trajectories";

  std::vector<StampedPose> gt, full_realtime, full_optimised;
  ASSERT_TRUE(readTumTrajectory(data + "/groundtruth.txt", &gt).ok());
  ASSERT_TRUE(readTumTrajectory(dir.file("full.txt"), &full_realtime).ok());
  ASSERT_TRUE(readTumTrajectory(dir.file("full_opt.txt"), &full_optimised).ok());
  const double ate_realtime = ateOf(gt, full_realtime), ate_optimised = ateOf(gt, full_optimised);
  // Like with like: real time joined with real time, optimised with optimised. (The map is the first
  // run's optimised graph, so the loaded run continues in the frame of its --out-optimized.)
  const std::vector<StampedPose> joined_realtime = concatenated(dir.file("a.txt"), dir.file("b.txt"));
  const std::vector<StampedPose> joined_optimised = concatenated(dir.file("a_opt.txt"), dir.file("b_opt.txt"));
  ASSERT_EQ(joined_realtime.size(), 250u);
  ASSERT_EQ(joined_optimised.size(), 250u);
  const double ate_joined_realtime = ateOf(gt, joined_realtime), ate_joined_optimised = ateOf(gt, joined_optimised);
  std::printf("head250 map reuse (two folders): relocalized at frame %d; real time: continuous %.4f m, joined %.4f m "
              "(%.2fx); optimised: continuous %.4f m, joined %.4f m (%.2fx)\n",
              relocalized, ate_realtime, ate_joined_realtime, ate_joined_realtime / ate_realtime, ate_optimised,
              ate_joined_optimised, ate_joined_optimised / ate_optimised);
  RecordProperty("ate_continuous_m", std::to_string(ate_realtime));
  RecordProperty("ate_joined_m", std::to_string(ate_joined_realtime));
  RecordProperty("ate_continuous_optimised_m", std::to_string(ate_optimised));
  RecordProperty("ate_joined_optimised_m", std::to_string(ate_joined_optimised));
  // Issue 20's bound, 1.2x, for both kinds. (The optimised join was 1.21x while the loaded
  // keyframes' link to the new run's frame was the first run's real-time record instead of the
  // optimised pose the run relocalizes against: docs/LOOP.md "Map files".)
  EXPECT_LE(ate_joined_realtime, 1.2 * ate_realtime);
  EXPECT_LE(ate_joined_optimised, 1.2 * ate_optimised);
  // Loading took well under a second.
  std::ifstream json(dir.file("b.json"));
  const std::string stats((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
  std::smatch m;
  ASSERT_TRUE(std::regex_search(stats, m, std::regex("\"load_read_ms\": ([0-9.]+), \"load_restore_ms\": ([0-9.]+)")));
  EXPECT_LT(std::stod(m[1]) + std::stod(m[2]), 500.0);
}

}  // namespace
}  // namespace plumb::test

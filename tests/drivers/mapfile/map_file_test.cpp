// Map files (docs/LOOP.md "Map files"): the container (drivers/mapfile/map_file.h) around the codec
// (pipeline/loop/saved_map_codec.h) and the loop closer's export/restore. A round trip is
// byte-exact; every damaged or foreign file is refused with a Status that says what is wrong.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "drivers/mapfile/map_file.h"
#include "drivers/recording/crc32.h"
#include "pipeline/loop/loop_closer.h"
#include "pipeline/loop/saved_map_codec.h"
#include "tests/support/plumb_cli.h"
#include "tests/support/saved_map_example.h"

namespace plumb::test {
namespace {

std::vector<uint8_t> fileBytes(const loop::SavedMap& map) {
  std::vector<loop::MapSectionBytes> sections;
  loop::encodeSavedMap(map, &sections);
  std::vector<MapFileSection> file_sections;
  for (auto& s : sections) file_sections.push_back(MapFileSection{s.tag, s.bytes});
  return encodeMapFile(loop::kSavedMapFormatVersion, file_sections);
}

Status parseAndDecode(const uint8_t* data, std::size_t size, loop::SavedMap* map) {
  std::vector<MapFileSection> file_sections;
  PLUMB_RETURN_IF_ERROR(parseMapFile(data, size, loop::kSavedMapFormatVersion, MapFileLimits{}, &file_sections));
  std::vector<loop::MapSectionBytes> sections;
  for (auto& s : file_sections) sections.push_back(loop::MapSectionBytes{s.tag, s.bytes});
  return loop::decodeSavedMap(sections, loop::SavedMapLimits{}, map);
}

loop::LoopCloser makeCloser(int capacity = 256) {
  const PinholeCamera c = exampleMapCamera();
  loop::LoopCloserOptions options;
  options.capacity = capacity;
  return loop::LoopCloser(CameraIntrinsics{c.fx, c.fy, c.cx, c.cy, c.fx * c.baseline_m}, NoiseModelOptions{}, options);
}

// Rewrites a section's payload (found by tag) and fixes its CRC, so only the codec can object.
std::vector<uint8_t> withSection(const loop::SavedMap& map, uint32_t tag,
                                 void (*edit)(std::vector<uint8_t>& payload)) {
  std::vector<loop::MapSectionBytes> sections;
  loop::encodeSavedMap(map, &sections);
  std::vector<MapFileSection> file_sections;
  for (auto& s : sections) {
    if (s.tag == tag) edit(s.bytes);
    file_sections.push_back(MapFileSection{s.tag, s.bytes});
  }
  return encodeMapFile(loop::kSavedMapFormatVersion, file_sections);
}

void putU32(std::vector<uint8_t>& b, std::size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + std::size_t(i)] = uint8_t(v >> (8 * i));
}

TEST(MapFile, RoundTripThroughTheLoopCloserIsByteExact) {
  loop::SavedMap original;
  makeExampleMap(42, 12, 300, 60, 3, &original);
  const std::vector<uint8_t> first = fileBytes(original);

  // Through a real file (AtomicFile) and back.
  ScratchDir dir("plumb_map_file");
  ASSERT_TRUE(dir.ok());
  std::vector<MapFileSection> sections;
  {
    std::vector<loop::MapSectionBytes> s;
    loop::encodeSavedMap(original, &s);
    for (auto& x : s) sections.push_back(MapFileSection{x.tag, x.bytes});
  }
  ASSERT_TRUE(writeMapFile(dir.file("a.map"), loop::kSavedMapFormatVersion, sections).ok());
  std::ifstream in(dir.file("a.map"), std::ios::binary);
  const std::vector<uint8_t> on_disk((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(on_disk, first);
  std::vector<MapFileSection> read_back;
  ASSERT_TRUE(readMapFile(dir.file("a.map"), loop::kSavedMapFormatVersion, MapFileLimits{}, &read_back).ok());

  loop::SavedMap decoded;
  const Status st = parseAndDecode(first.data(), first.size(), &decoded);
  ASSERT_TRUE(st.ok()) << st.message();
  // Field by field against the original (an oracle independent of the encoder).
  ASSERT_EQ(decoded.keyframes.size(), original.keyframes.size());
  for (std::size_t i = 0; i < original.keyframes.size(); ++i) {
    const loop::SavedKeyframe& a = *original.keyframes[i];
    const loop::SavedKeyframe& b = *decoded.keyframes[i];
    EXPECT_EQ(a.record.id, b.record.id);
    EXPECT_EQ(a.record.timestamp_s, b.record.timestamp_s);
    EXPECT_TRUE(a.T_world_cam.matrix() == b.T_world_cam.matrix());
    EXPECT_TRUE(a.edge_covariance == b.edge_covariance);
    ASSERT_EQ(a.record.points.size(), b.record.points.size());
    ASSERT_EQ(a.record.lines.size(), b.record.lines.size());
    for (std::size_t p = 0; p < a.record.points.size(); ++p) {
      EXPECT_TRUE(a.record.points[p].P_cam == b.record.points[p].P_cam);
      EXPECT_EQ(a.record.point_descriptors[p].words, b.record.point_descriptors[p].words);
    }
    for (std::size_t l = 0; l < a.record.lines.size(); ++l) {
      EXPECT_EQ(a.record.lines[l].num_samples, b.record.lines[l].num_samples);
      EXPECT_TRUE(a.record.lines[l].samples_cam[1] == b.record.lines[l].samples_cam[1]);
    }
  }
  EXPECT_EQ(decoded.loop_edges.size(), 3u);
  EXPECT_TRUE(loop::cameraMismatch(decoded.camera, original.camera).empty());

  // Into a loop closer and out again: the same bytes.
  loop::LoopCloser closer = makeCloser();
  ASSERT_TRUE(closer.restoreMap(decoded).ok());
  EXPECT_EQ(closer.size(), 12u);
  Eigen::Isometry3d T;
  ASSERT_TRUE(closer.pose(original.keyframes[5]->record.id, &T));
  EXPECT_TRUE(T.matrix() == original.keyframes[5]->T_world_cam.matrix());
  loop::SavedMap exported;
  closer.exportMap(&exported);
  exported.camera = decoded.camera;
  EXPECT_EQ(fileBytes(exported), first);
  // A closer refuses a second map (it is not empty any more).
  EXPECT_FALSE(closer.restoreMap(decoded).ok());
}

// The loading run relocalizes against the loaded keyframes at their OPTIMISED poses, so its mapping
// frame is the map's graph frame: a new keyframe of that run enters the graph at its own pose. (It
// was placed through the last loaded keyframe's real-time record, which the example map draws
// independently of its optimised pose, as a first run's corrections make them differ: the whole
// second run's optimised output moved by that difference; docs/LOOP.md "Map files".)
TEST(MapFile, ANewKeyframeAfterALoadedMapEntersTheGraphAtItsOwnPose) {
  loop::SavedMap map;
  makeExampleMap(7, 6, 10, 2, 1, &map);
  ASSERT_FALSE(map.keyframes.back()->record.T_world_cam.isApprox(map.keyframes.back()->T_world_cam, 1e-3));
  loop::LoopCloser closer = makeCloser();
  ASSERT_TRUE(closer.restoreMap(map).ok());
  auto record = std::make_unique<loop::LoopKeyframe>();
  record->id = map.maxKeyframeId() + 40;
  record->new_segment = true;
  record->T_world_cam = map.keyframes.back()->T_world_cam *
                        Eigen::Isometry3d(Eigen::Translation3d(0.1, -0.05, 0.2) * Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()));
  (void)closer.addKeyframe(*record);
  Eigen::Isometry3d T;
  ASSERT_TRUE(closer.pose(record->id, &T));
  EXPECT_TRUE(T.isApprox(record->T_world_cam, 1e-12)) << T.matrix() << "\n" << record->T_world_cam.matrix();
}

TEST(MapFile, RestoreRefusesWhatTheCloserCannotHold) {
  loop::SavedMap map;
  makeExampleMap(3, 5, 10, 2, 1, &map);
  loop::LoopCloser small = makeCloser(4);
  const Status st = small.restoreMap(map);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("capacity"), std::string::npos) << st.message();
  map.keyframes[2]->edge_covariance = -Matrix6d::Identity();
  loop::LoopCloser closer = makeCloser();
  EXPECT_FALSE(closer.restoreMap(map).ok());
  EXPECT_EQ(closer.size(), 0u);  // nothing changed
}

TEST(MapFile, EveryTruncationIsRefused) {
  loop::SavedMap map;
  makeExampleMap(7, 3, 12, 4, 1, &map);
  const std::vector<uint8_t> bytes = fileBytes(map);
  ASSERT_GT(bytes.size(), 2000u);
  for (std::size_t size = 0; size < bytes.size(); ++size) {
    loop::SavedMap out;
    const Status st = parseAndDecode(bytes.data(), size, &out);
    ASSERT_FALSE(st.ok()) << "truncated to " << size << " bytes was accepted";
    if (size >= kMapFileHeaderBytes) {
      EXPECT_NE(st.message().find("truncated"), std::string::npos) << st.message();
    }
  }
  loop::SavedMap whole;
  EXPECT_TRUE(parseAndDecode(bytes.data(), bytes.size(), &whole).ok());
  // And one byte too many.
  std::vector<uint8_t> longer = bytes;
  longer.push_back(0);
  EXPECT_FALSE(parseAndDecode(longer.data(), longer.size(), &whole).ok());
}

TEST(MapFile, AFlippedByteAnywhereIsRefused) {
  loop::SavedMap map;
  makeExampleMap(9, 3, 12, 4, 1, &map);
  const std::vector<uint8_t> bytes = fileBytes(map);
  for (std::size_t at = 0; at < bytes.size(); ++at) {
    for (uint8_t mask : {uint8_t(0x01), uint8_t(0x80), uint8_t(0xFF)}) {
      std::vector<uint8_t> damaged = bytes;
      damaged[at] ^= mask;
      loop::SavedMap out;
      ASSERT_FALSE(parseAndDecode(damaged.data(), damaged.size(), &out).ok())
          << "byte " << at << " ^ " << int(mask) << " was accepted";
    }
  }
}

TEST(MapFile, FutureVersionAndWrongMagicAreRefused) {
  loop::SavedMap map;
  makeExampleMap(11, 2, 5, 1, 0, &map);
  std::vector<uint8_t> future = fileBytes(map);
  putU32(future, 8, loop::kSavedMapFormatVersion + 1);
  putU32(future, 28, crc32(future.data(), 28));  // a valid header of a newer format
  loop::SavedMap out;
  Status st = parseAndDecode(future.data(), future.size(), &out);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("newer plumb"), std::string::npos) << st.message();

  std::vector<uint8_t> magic = fileBytes(map);
  std::memcpy(magic.data(), "PLUMBREC", 8);
  st = parseAndDecode(magic.data(), magic.size(), &out);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("magic"), std::string::npos) << st.message();
}

TEST(MapFile, CountsBeyondTheirBoundsAreRefusedBeforeAllocation) {
  loop::SavedMap map;
  makeExampleMap(13, 2, 5, 2, 1, &map);
  loop::SavedMap out;
  struct Case {
    uint32_t tag;
    void (*edit)(std::vector<uint8_t>&);
    const char* expect;
  } cases[] = {
      {loop::kSectionKeyframes, [](std::vector<uint8_t>& b) { putU32(b, 0, 0xFFFFFFFFu); }, "exceeds the bound"},
      {loop::kSectionKeyframes, [](std::vector<uint8_t>& b) { putU32(b, 0, 4000); }, "needs more bytes"},
      {loop::kSectionLoopEdges, [](std::vector<uint8_t>& b) { putU32(b, 0, 0x7FFFFFFFu); }, "exceeds the bound"},
      // The first keyframe's point count: after the fixed fields (4+8+8+1+4 + 2 poses + mat6 + 1 +
      // pose + 1 + pose + mat6 + 8 + 4 bytes) and the keyframe count.
      {loop::kSectionKeyframes,
       [](std::vector<uint8_t>& b) { putU32(b, 4 + 25 + 2 * 96 + 288 + 1 + 96 + 1 + 96 + 288 + 8 + 4, 501); },
       "points count 501"},
      {loop::kSectionKeyframes, [](std::vector<uint8_t>& b) { b.push_back(0); }, "after the last field"},
      {loop::kSectionCamera, [](std::vector<uint8_t>& b) { putU32(b, 72, 100000); }, "exceeds 8192"},
  };
  for (const Case& c : cases) {
    const std::vector<uint8_t> bytes = withSection(map, c.tag, c.edit);
    const Status st = parseAndDecode(bytes.data(), bytes.size(), &out);
    ASSERT_FALSE(st.ok()) << c.expect;
    EXPECT_NE(st.message().find(c.expect), std::string::npos) << st.message();
  }
}

TEST(MapFile, BadValuesBehindValidChecksumsAreRefused) {
  loop::SavedMap out;
  {
    loop::SavedMap map;
    makeExampleMap(17, 3, 4, 1, 0, &map);
    map.keyframes[1]->T_world_cam.translation().x() = std::nan("");
    const std::vector<uint8_t> bytes = fileBytes(map);
    const Status st = parseAndDecode(bytes.data(), bytes.size(), &out);
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.message().find("not finite"), std::string::npos) << st.message();
  }
  {
    loop::SavedMap map;
    makeExampleMap(17, 3, 4, 1, 0, &map);
    map.keyframes[2]->record.id = map.keyframes[1]->record.id;
    const std::vector<uint8_t> bytes = fileBytes(map);
    EXPECT_FALSE(parseAndDecode(bytes.data(), bytes.size(), &out).ok());
  }
  {
    loop::SavedMap map;
    makeExampleMap(17, 3, 4, 1, 1, &map);
    map.loop_edges[0].candidate_id = 999;
    const std::vector<uint8_t> bytes = fileBytes(map);
    const Status st = parseAndDecode(bytes.data(), bytes.size(), &out);
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.message().find("does not hold"), std::string::npos) << st.message();
  }
  {
    loop::SavedMap map;
    makeExampleMap(17, 3, 4, 1, 0, &map);
    map.keyframes[0]->T_world_cam.linear() *= 1.01;  // not a rotation
    const std::vector<uint8_t> bytes = fileBytes(map);
    EXPECT_FALSE(parseAndDecode(bytes.data(), bytes.size(), &out).ok());
  }
}

TEST(MapFile, AnotherCameraIsNamed) {
  const PinholeCamera a = exampleMapCamera();
  EXPECT_TRUE(loop::cameraMismatch(a, a).empty());
  PinholeCamera b = a;
  b.fx += 1;
  EXPECT_NE(loop::cameraMismatch(a, b).find("fx"), std::string::npos);
  b = a;
  b.width = 320;
  EXPECT_NE(loop::cameraMismatch(a, b).find("image size"), std::string::npos);
  b = a;
  b.depth_factor = 1000;
  EXPECT_NE(loop::cameraMismatch(a, b).find("depth factor"), std::string::npos);
}

}  // namespace
}  // namespace plumb::test

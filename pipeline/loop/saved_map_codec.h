#pragma once
// The bytes of a SavedMap (saved_map.h): one payload per section, little-endian, no padding. The
// container around them (magic, version, sizes, a CRC-32 per section) is drivers/mapfile/map_file.h;
// this codec never sees a file. Layout of format version kSavedMapFormatVersion (docs/LOOP.md
// "Map files"):
//
//   CAMR  f64 fx fy cx cy k1 k2 p1 p2 k3, i32 width height, f64 depth_factor baseline_m
//         rolling_shutter_readout_s
//   KFRM  u32 count, then per keyframe (ascending id):
//           u32 id, u64 frame_sequence, f64 timestamp_s, u8 new_segment, u32 previous_id,
//           pose T_previous_this, pose T_world_cam (at creation), mat6 covariance, u8 valid,
//           pose T_world_cam (graph), u8 has_edge, pose T_previous_this (graph edge),
//           mat6 edge_covariance, f64 edge_length_m, u32 previous_map_id,
//           u32 points, per point f32 P_cam[3] px[2] u_right, i8 octave, u64 descriptor[4],
//           u32 lines, per line f32 l[3], i8 octave, u8 samples, f32 sample[3] x samples,
//           u64 descriptor[4]
//   LOOP  u32 count, per edge u32 candidate_id query_id, pose T_candidate_query, mat6 information
//   (pose = 12 f64: rotation row-major, then translation; mat6 = 36 f64 row-major)
//
// decodeSavedMap trusts nothing: every count is checked against its hard bound AND against the
// bytes left before anything is allocated for it, every number must be finite, rotations
// orthonormal, ids strictly ascending, loop edges between stored keyframes, and a section must be
// consumed exactly. The CRCs are the container's job; this is what stands between a file that
// passed them (or a fuzzer) and the loop closer.
#include <cstdint>
#include <vector>

#include "pipeline/loop/saved_map.h"
#include "platform/status.h"

namespace plumb::loop {

constexpr uint32_t kSavedMapFormatVersion = 1;
// The largest keyframe id a map may hold (2^31 - 1): a run that loads it numbers new keyframes
// after it, so 2^31 ids stay free (68 years at one keyframe a second) and ids never wrap.
constexpr uint32_t kMaxSavedKeyframeId = 0x7FFFFFFFu;

constexpr uint32_t sectionTag(char a, char b, char c, char d) {
  return uint32_t(uint8_t(a)) | uint32_t(uint8_t(b)) << 8 | uint32_t(uint8_t(c)) << 16 | uint32_t(uint8_t(d)) << 24;
}
constexpr uint32_t kSectionCamera = sectionTag('C', 'A', 'M', 'R');
constexpr uint32_t kSectionKeyframes = sectionTag('K', 'F', 'R', 'M');
constexpr uint32_t kSectionLoopEdges = sectionTag('L', 'O', 'O', 'P');

struct MapSectionBytes {
  uint32_t tag = 0;
  std::vector<uint8_t> bytes;
};

// Hard bounds of a decoded map (a file beyond them is refused before allocation).
struct SavedMapLimits {
  std::size_t max_keyframes = 4096;
  std::size_t max_loop_edges = 4096;
};

// The three sections, in the order above.
void encodeSavedMap(const SavedMap& map, std::vector<MapSectionBytes>* sections);
// Each section exactly once; unknown tags are refused (a future layout has a new version).
Status decodeSavedMap(const std::vector<MapSectionBytes>& sections, const SavedMapLimits& limits, SavedMap* map);

}  // namespace plumb::loop

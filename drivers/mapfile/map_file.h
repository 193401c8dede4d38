#pragma once
// The map file container (docs/LOOP.md "Map files"): a header and checksummed sections, each an
// opaque payload (the loop closer's map, encoded by pipeline/loop/saved_map_codec.h; drivers/ never
// sees pipeline types). Little-endian:
//
//   header (32 bytes)  "PLUMBMAP"  u32 version  u32 section_count  u64 file_size  u32 reserved (0)
//                      u32 CRC-32 of the 28 bytes before it
//   section (x count)  u32 tag  u32 reserved (0)  u64 payload_size  payload  u32 CRC-32 of tag,
//                      reserved, size and payload
//   nothing after the last section (file_size says where the file ends).
//
// CRC-32 is the recording format's (drivers/recording/crc32.h). The reader refuses, with a message
// that says which and where: a wrong magic, a future (or unknown) version, a file whose size is not
// the header's (truncated or grown), a header or section CRC mismatch, a section count or size
// beyond the limits or beyond the bytes left; all before anything is allocated for a section.
// A file is written through AtomicFile: it appears under its name only when complete.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "platform/status.h"

namespace plumb {

constexpr std::size_t kMapFileHeaderBytes = 32;
constexpr std::size_t kMapFileSectionOverheadBytes = 20;  // tag, reserved, size, CRC

struct MapFileSection {
  uint32_t tag = 0;
  std::vector<uint8_t> bytes;
};

struct MapFileLimits {
  uint64_t max_file_bytes = uint64_t(1) << 30;  // 1 GiB; a 256-keyframe map is ~10 MB
  uint32_t max_sections = 16;
};

// The whole file's bytes.
std::vector<uint8_t> encodeMapFile(uint32_t version, const std::vector<MapFileSection>& sections);
// Parses bytes (a file's content or a fuzzer's input). `supported_version` is the one this build
// reads; a larger one is refused as written by a newer plumb.
Status parseMapFile(const uint8_t* data, std::size_t size, uint32_t supported_version, const MapFileLimits& limits,
                    std::vector<MapFileSection>* sections);

// File I/O around the two above; errors name the path.
Status readMapFile(const std::string& path, uint32_t supported_version, const MapFileLimits& limits,
                   std::vector<MapFileSection>* sections);
Status writeMapFile(const std::string& path, uint32_t version, const std::vector<MapFileSection>& sections);

}  // namespace plumb

#pragma once
// The .plumbrec recording format (byte-by-byte layout in docs/DRIVERS.md). All integers and
// doubles little-endian; doubles are IEEE-754 binary64.
//
//   file   = FileHeader chunk*
//   chunk  = ChunkHeader payload chunk_crc
//   FileHeader (124 bytes; 260 in version 3): "PLUMBREC", version, header size, camera, [depth
//              camera,] header CRC
//   ChunkHeader (16 bytes): "PLCK", type, payload size, CRC of these 12 bytes
//   chunk_crc (4 bytes): CRC-32 of ChunkHeader + payload
//
// Chunk types: kFrame (one RGB-D frame), kIndex (where the frames since the previous index are),
// kEnd (written last by close(): where the final index is). A reader never needs the index: it
// walks the chunks, and on damage resynchronises on the next "PLCK" whose header CRC holds.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "sensor/camera.h"
#include "platform/status.h"

namespace plumb {

constexpr char kRecordingMagic[8] = {'P', 'L', 'U', 'M', 'B', 'R', 'E', 'C'};
// Version 2 added the camera's rolling-shutter readout time (version 1 files are refused).
constexpr uint32_t kRecordingVersion = 2;
constexpr std::size_t kFileHeaderSize = 124;
// Version 3: version 2's header with the unregistered depth camera (PinholeCamera::depth_camera)
// after the camera; written only for such a camera, so every other recording stays version 2 byte
// for byte. Its frames' depth images have the depth camera's size.
constexpr uint32_t kRecordingVersionDepthCamera = 3;
constexpr std::size_t kFileHeaderSizeDepthCamera = 260;
constexpr std::size_t kMaxFileHeaderSize = kFileHeaderSizeDepthCamera;

constexpr char kChunkMagic[4] = {'P', 'L', 'C', 'K'};
constexpr std::size_t kChunkHeaderSize = 16;
constexpr std::size_t kChunkCrcSize = 4;
// A header declaring more than this is treated as damage: no sane frame is this large
// (a raw 4K BGR + depth frame is ~37 MiB), and it bounds what a corrupt size can make us read.
constexpr uint32_t kMaxChunkPayload = 256u << 20;

enum class ChunkType : uint32_t { kFrame = 1, kIndex = 2, kEnd = 3 };

// How an image is stored inside a frame chunk. Both are lossless.
enum class ImageCodec : uint8_t {
  kRaw = 0,  // rows top to bottom, no padding: BGR bytes, or uint16 little-endian depth
  kPng = 1,  // PNG (8-bit BGR colour, 16-bit grey depth) via libpng (drivers/image/png_encoder.h)
};

constexpr std::size_t kFramePayloadFixedSize = 64;
constexpr std::size_t kIndexPayloadFixedSize = 16;  // previous index offset, count, reserved
constexpr std::size_t kIndexEntrySize = 24;
constexpr std::size_t kEndPayloadSize = 16;

// Fields of a frame chunk before the image bytes.
struct FrameChunkInfo {
  uint64_t sequence = 0;
  double timestamp_s = 0;
  double depth_timestamp_s = 0;
  int64_t t_sensor_ns = 0;  // host monotonic capture time at recording
  int32_t width = 0, height = 0;
  double depth_factor = 0;
  ImageCodec colour_codec = ImageCodec::kPng;
  ImageCodec depth_codec = ImageCodec::kPng;
  uint32_t colour_size = 0;
  uint32_t depth_size = 0;
};

struct IndexEntry {
  uint64_t sequence = 0;
  double timestamp_s = 0;
  uint64_t chunk_offset = 0;  // byte offset of the frame chunk's "PLCK"
};

// File header <-> bytes (version 2, or 3 for a camera with a depth camera). decode checks magic,
// version, size, CRC and the camera's validity, and says how long the header was.
void encodeFileHeader(const PinholeCamera& camera, std::vector<uint8_t>& out);
Status decodeFileHeader(const uint8_t* bytes, std::size_t size, PinholeCamera* camera,
                        std::size_t* header_size = nullptr);

// Chunk header fields; decode returns false unless magic and header CRC hold and the size is sane.
struct ChunkHeader {
  ChunkType type = ChunkType::kFrame;
  uint32_t payload_size = 0;
};
void beginChunk(ChunkType type, std::vector<uint8_t>& out);  // header with size 0, patched later
void endChunk(std::size_t chunk_start, std::vector<uint8_t>& out);  // patch size + CRCs
bool decodeChunkHeader(const uint8_t* bytes, ChunkHeader* header);
// True when the CRC at the end of a complete chunk (header + payload + crc) matches.
bool chunkCrcMatches(const uint8_t* chunk, std::size_t payload_size);

void encodeFrameInfo(const FrameChunkInfo& info, std::vector<uint8_t>& out);
bool decodeFrameInfo(const uint8_t* payload, std::size_t payload_size, FrameChunkInfo* info);

}  // namespace plumb

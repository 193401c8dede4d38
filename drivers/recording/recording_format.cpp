#include "drivers/recording/recording_format.h"

#include <cstring>

#include "drivers/recording/byte_io.h"
#include "drivers/recording/crc32.h"

namespace plumb {
// Stored image sizes are bounded by the camera contract's kMaxImageSide (sensor/camera.h): larger
// values can only come from a damaged or foreign file.

void encodeFileHeader(const PinholeCamera& camera, std::vector<uint8_t>& out) {
  const std::size_t start = out.size();
  const bool depth_camera = camera.depth_camera.has_value();
  ByteWriter w(out);
  w.bytes(kRecordingMagic, sizeof kRecordingMagic);
  w.u32(depth_camera ? kRecordingVersionDepthCamera : kRecordingVersion);
  w.u32(static_cast<uint32_t>(depth_camera ? kFileHeaderSizeDepthCamera : kFileHeaderSize));
  for (double v : {camera.fx, camera.fy, camera.cx, camera.cy, camera.k1, camera.k2, camera.p1,
                   camera.p2, camera.k3, camera.depth_factor, camera.baseline_m, camera.rolling_shutter_readout_s}) {
    w.f64(v);
  }
  w.i32(camera.width);
  w.i32(camera.height);
  if (depth_camera) {
    const DepthCamera& d = *camera.depth_camera;
    for (double v : {d.fx, d.fy, d.cx, d.cy, d.k1, d.k2, d.p1, d.p2, d.k3}) w.f64(v);
    w.i32(d.width);
    w.i32(d.height);
    for (double v : {d.qx, d.qy, d.qz, d.qw, d.tx, d.ty, d.tz}) w.f64(v);
  }
  w.u32(crc32(out.data() + start, out.size() - start));
}

Status decodeFileHeader(const uint8_t* bytes, std::size_t size, PinholeCamera* camera, std::size_t* header_size_out) {
  if (size < kFileHeaderSize)
    return Status::Error("file header truncated (" + std::to_string(size) + " of " +
                         std::to_string(kFileHeaderSize) + " bytes)");
  if (std::memcmp(bytes, kRecordingMagic, sizeof kRecordingMagic) != 0)
    return Status::Error("not a plumb recording (magic is not PLUMBREC)");
  ByteReader r(bytes + 8, size - 8);
  const uint32_t version = r.u32();
  const uint32_t header_size = r.u32();
  if (version != kRecordingVersion && version != kRecordingVersionDepthCamera)
    return Status::Error("unsupported recording version " + std::to_string(version) + " (this build reads versions " +
                         std::to_string(kRecordingVersion) + " and " + std::to_string(kRecordingVersionDepthCamera) +
                         ")");
  const bool depth_camera = version == kRecordingVersionDepthCamera;
  const std::size_t expected_size = depth_camera ? kFileHeaderSizeDepthCamera : kFileHeaderSize;
  if (header_size != expected_size)
    return Status::Error("file header size " + std::to_string(header_size) + " is not " +
                         std::to_string(expected_size));
  if (size < expected_size)
    return Status::Error("file header truncated (" + std::to_string(size) + " of " + std::to_string(expected_size) +
                         " bytes)");
  const uint32_t expected_crc = crc32(bytes, expected_size - 4);
  PinholeCamera c;
  for (double* v : {&c.fx, &c.fy, &c.cx, &c.cy, &c.k1, &c.k2, &c.p1, &c.p2, &c.k3,
                    &c.depth_factor, &c.baseline_m, &c.rolling_shutter_readout_s}) {
    *v = r.f64();
  }
  c.width = r.i32();
  c.height = r.i32();
  if (depth_camera) {
    DepthCamera d;
    for (double* v : {&d.fx, &d.fy, &d.cx, &d.cy, &d.k1, &d.k2, &d.p1, &d.p2, &d.k3}) *v = r.f64();
    d.width = r.i32();
    d.height = r.i32();
    for (double* v : {&d.qx, &d.qy, &d.qz, &d.qw, &d.tx, &d.ty, &d.tz}) *v = r.f64();
    c.depth_camera = d;
  }
  if (r.u32() != expected_crc) return Status::Error("file header CRC mismatch (header damaged)");
  if (c.width > kMaxImageSide || c.height > kMaxImageSide)
    return Status::Error("file header: image size out of range");
  const std::string problem = c.validate();
  if (!problem.empty()) return Status::Error("file header: camera invalid: " + problem);
  *camera = c;
  if (header_size_out != nullptr) *header_size_out = expected_size;
  return Status::Ok();
}

void beginChunk(ChunkType type, std::vector<uint8_t>& out) {
  ByteWriter w(out);
  w.bytes(kChunkMagic, sizeof kChunkMagic);
  w.u32(static_cast<uint32_t>(type));
  w.u32(0);  // payload size, patched by endChunk
  w.u32(0);  // header CRC, patched by endChunk
}

void endChunk(std::size_t chunk_start, std::vector<uint8_t>& out) {
  ByteWriter w(out);
  const std::size_t payload_size = out.size() - chunk_start - kChunkHeaderSize;
  w.patchU32(chunk_start + 8, static_cast<uint32_t>(payload_size));
  w.patchU32(chunk_start + 12, crc32(out.data() + chunk_start, 12));
  w.u32(crc32(out.data() + chunk_start, out.size() - chunk_start));
}

bool decodeChunkHeader(const uint8_t* bytes, ChunkHeader* header) {
  if (std::memcmp(bytes, kChunkMagic, sizeof kChunkMagic) != 0) return false;
  ByteReader r(bytes + 4, kChunkHeaderSize - 4);
  const uint32_t type = r.u32();
  const uint32_t payload_size = r.u32();
  if (r.u32() != crc32(bytes, 12)) return false;
  if (type < 1 || type > 3 || payload_size > kMaxChunkPayload) return false;
  header->type = static_cast<ChunkType>(type);
  header->payload_size = payload_size;
  return true;
}

bool chunkCrcMatches(const uint8_t* chunk, std::size_t payload_size) {
  const std::size_t covered = kChunkHeaderSize + payload_size;
  ByteReader r(chunk + covered, kChunkCrcSize);
  return r.u32() == crc32(chunk, covered);
}

void encodeFrameInfo(const FrameChunkInfo& info, std::vector<uint8_t>& out) {
  ByteWriter w(out);
  w.u64(info.sequence);
  w.f64(info.timestamp_s);
  w.f64(info.depth_timestamp_s);
  w.i64(info.t_sensor_ns);
  w.i32(info.width);
  w.i32(info.height);
  w.f64(info.depth_factor);
  w.u8(static_cast<uint8_t>(info.colour_codec));
  w.u8(static_cast<uint8_t>(info.depth_codec));
  w.u16(0);
  w.u32(info.colour_size);
  w.u32(info.depth_size);
  w.u32(0);
}

bool decodeFrameInfo(const uint8_t* payload, std::size_t payload_size, FrameChunkInfo* info) {
  ByteReader r(payload, payload_size);
  FrameChunkInfo f;
  f.sequence = r.u64();
  f.timestamp_s = r.f64();
  f.depth_timestamp_s = r.f64();
  f.t_sensor_ns = r.i64();
  f.width = r.i32();
  f.height = r.i32();
  f.depth_factor = r.f64();
  const uint8_t colour_codec = r.u8();
  const uint8_t depth_codec = r.u8();
  r.u16();
  f.colour_size = r.u32();
  f.depth_size = r.u32();
  r.u32();
  if (!r.ok() || colour_codec > 1 || depth_codec > 1) return false;
  if (f.width <= 0 || f.height <= 0 || f.width > kMaxImageSide || f.height > kMaxImageSide)
    return false;
  if (static_cast<uint64_t>(f.colour_size) + f.depth_size != r.remaining()) return false;
  f.colour_codec = static_cast<ImageCodec>(colour_codec);
  f.depth_codec = static_cast<ImageCodec>(depth_codec);
  *info = f;
  return true;
}

}  // namespace plumb

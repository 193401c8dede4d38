#include "drivers/recording/recording_source.h"

#include <unistd.h>

#include <cmath>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

#include "drivers/recording/byte_io.h"
#include "drivers/recording/frame_codec.h"
#include "platform/input_file.h"

namespace plumb {
namespace {

constexpr std::size_t kScanWindow = 64 * 1024;

int64_t monotonicNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

Status openFile(const std::string& path, std::FILE** file, uint64_t* size) {
  // Opened the one way (platform/input_file.h): a FIFO or a device is refused, never blocks.
  InputFile input;
  PLUMB_RETURN_IF_ERROR(input.open(path, UINT64_MAX, "recording"));
  const int fd = ::dup(input.fd());
  *file = fd >= 0 ? ::fdopen(fd, "rb") : nullptr;
  if (!*file) {
    if (fd >= 0) ::close(fd);
    return Status::Error(path + ": cannot open: " + std::strerror(errno));
  }
  if (fseeko(*file, 0, SEEK_END) != 0) return Status::Error(path + ": cannot seek");
  *size = static_cast<uint64_t>(ftello(*file));
  return Status::Ok();
}

}  // namespace

Status RecordingSource::open(const std::string& path, std::unique_ptr<RecordingSource>* out) {
  std::unique_ptr<RecordingSource> source(new RecordingSource());
  source->path_ = path;
  PLUMB_RETURN_IF_ERROR(openFile(path, &source->file_, &source->file_size_));
  uint8_t header[kMaxFileHeaderSize];
  const std::size_t n = source->readAt(0, header, sizeof header);
  PLUMB_RETURN_IF_ERROR(decodeFileHeader(header, n, &source->camera_, &source->header_size_).withContext(path));
  source->pos_ = source->header_size_;
  source->scan_.resize(kScanWindow);
  *out = std::move(source);
  return Status::Ok();
}

RecordingSource::~RecordingSource() {
  if (file_) std::fclose(file_);
}

void RecordingSource::rewind() {
  pos_ = header_size_;
  stats_ = RecordingStats();
  has_last_timestamp_ = false;
  last_error_ = Status::Ok();
}

SourceDamage RecordingSource::damage() const {
  SourceDamage d;
  d.regions_skipped = stats_.chunks_skipped;
  d.bytes_skipped = stats_.bytes_skipped;
  d.truncated_tail_bytes = stats_.truncated_tail_bytes;
  d.closed_properly = stats_.end_chunk_seen;
  d.last = stats_.last_damage;
  return d;
}

Status RecordingSource::overrideCamera(const PinholeCamera& camera) {
  if (camera.width != camera_.width || camera.height != camera_.height)
    return Status::Error(path_ + ": camera is " + std::to_string(camera.width) + "x" +
                         std::to_string(camera.height) + " but the recording is " +
                         std::to_string(camera_.width) + "x" + std::to_string(camera_.height));
  // Its depth images have the recording's depth size: a depth camera of another size cannot have made them.
  if (camera.depthWidth() != camera_.depthWidth() || camera.depthHeight() != camera_.depthHeight())
    return Status::Error(path_ + ": the camera's depth camera is " + std::to_string(camera.depthWidth()) + "x" +
                         std::to_string(camera.depthHeight()) + " but the recording's depth images are " +
                         std::to_string(camera_.depthWidth()) + "x" + std::to_string(camera_.depthHeight()));
  camera_ = camera;
  return Status::Ok();
}

std::size_t RecordingSource::readAt(uint64_t offset, uint8_t* dst, std::size_t n) {
  if (fseeko(file_, static_cast<off_t>(offset), SEEK_SET) != 0) return 0;
  return std::fread(dst, 1, n, file_);
}

uint64_t RecordingSource::findNextChunk(uint64_t from) {
  uint64_t window_start = from;
  while (window_start + kChunkHeaderSize <= file_size_) {
    const std::size_t n = readAt(window_start, scan_.data(), scan_.size());
    if (n < kChunkHeaderSize) break;
    ChunkHeader header;
    for (std::size_t i = 0; i + kChunkHeaderSize <= n; ++i) {
      if (scan_[i] == kChunkMagic[0] && decodeChunkHeader(&scan_[i], &header))
        return window_start + i;
    }
    // Overlap the next window so a header straddling the boundary is still seen.
    window_start += n - (kChunkHeaderSize - 1);
  }
  return file_size_;
}

void RecordingSource::skipDamage(const char* why) {
  const uint64_t damage_start = pos_;
  const uint64_t next = findNextChunk(pos_ + 1);
  stats_.last_damage = "chunk at byte " + std::to_string(damage_start) + ": " + why;
  if (next < file_size_) {
    ++stats_.chunks_skipped;
    stats_.bytes_skipped += next - damage_start;
  } else {
    // Nothing recognisable follows: a torn write at the tail, not a skipped chunk.
    stats_.truncated_tail_bytes += file_size_ - damage_start;
  }
  pos_ = next;
}

SourceResult RecordingSource::next(RgbdImage& out) {
  while (pos_ < file_size_) {
    uint8_t header_bytes[kChunkHeaderSize];
    if (file_size_ - pos_ < kChunkHeaderSize) {
      stats_.truncated_tail_bytes += file_size_ - pos_;
      pos_ = file_size_;
      break;
    }
    ChunkHeader header;
    if (readAt(pos_, header_bytes, sizeof header_bytes) != sizeof header_bytes) {
      last_error_ = Status::Error(path_ + ": read failed at byte " + std::to_string(pos_));
      return SourceResult::kError;
    }
    if (!decodeChunkHeader(header_bytes, &header)) {
      skipDamage("bad chunk header");
      continue;
    }
    const uint64_t chunk_size = kChunkHeaderSize + header.payload_size + kChunkCrcSize;
    if (chunk_size > file_size_ - pos_) {
      // A header whose chunk runs past the end: the write was cut off -- unless a valid chunk
      // follows, in which case the header's size field is damaged (e.g. a flipped bit claiming
      // 256 MiB) and the later frames are still there.
      skipDamage("chunk size runs past the end of the file");
      continue;
    }
    chunk_.resize(chunk_size);
    if (readAt(pos_, chunk_.data(), chunk_size) != chunk_size) {
      last_error_ = Status::Error(path_ + ": read failed at byte " + std::to_string(pos_));
      return SourceResult::kError;
    }
    if (!chunkCrcMatches(chunk_.data(), header.payload_size)) {
      // Counted even if nothing follows: the chunk was complete, so this is damage, not a cut.
      const uint64_t damage_start = pos_;
      const uint64_t next = findNextChunk(pos_ + 1);
      ++stats_.chunks_skipped;
      stats_.bytes_skipped += next - damage_start;
      stats_.last_damage = "chunk at byte " + std::to_string(damage_start) + ": CRC mismatch";
      pos_ = next;
      continue;
    }
    const uint8_t* payload = chunk_.data() + kChunkHeaderSize;
    if (header.type == ChunkType::kIndex) {
      ++stats_.index_chunks;
      pos_ += chunk_size;
      continue;
    }
    if (header.type == ChunkType::kEnd) {
      stats_.end_chunk_seen = true;
      pos_ += chunk_size;
      continue;
    }
    FrameChunkInfo info;
    if (!decodeFrameInfo(payload, header.payload_size, &info) ||
        !decodeFrame(info, payload + kFramePayloadFixedSize, out)) {
      // CRC held, so the bytes are as written: a foreign or buggy writer. Skip and say so.
      ++stats_.chunks_skipped;
      stats_.bytes_skipped += chunk_size;
      stats_.last_damage = "chunk at byte " + std::to_string(pos_) + ": undecodable frame (bad image, size, timestamp or depth factor)";
      pos_ += chunk_size;
      continue;
    }
    pos_ += chunk_size;
    ++stats_.frames_read;
    return SourceResult::kFrame;
  }
  return SourceResult::kEndOfStream;
}

bool RecordingSource::decodeFrame(const FrameChunkInfo& info, const uint8_t* images,
                                  RgbdImage& out) {
  if (info.width != camera_.width || info.height != camera_.height) return false;
  // Time must be a number and move forward: a NaN, backwards or repeated timestamp (CRC intact, so
  // a foreign or buggy writer) would put a wrong line into every trajectory made from this file.
  // An absurd stamp (1e300, nanoseconds) is damage itself; it never becomes the reference that
  // would make every later, correct frame look like a step back in time.
  auto plausible = [](double t) { return std::isfinite(t) && t >= 0 && t <= kMaxTimestampS; };
  if (!plausible(info.timestamp_s) || !plausible(info.depth_timestamp_s) ||
      (has_last_timestamp_ && !(info.timestamp_s > last_timestamp_s_))) {
    return false;
  }
  // The depth scale of the frame must be a camera's (sensor/camera.h bounds), never 0 or NaN.
  if (!(info.depth_factor >= kCameraBounds.min_depth_factor && info.depth_factor <= kCameraBounds.max_depth_factor))
    return false;
  if (!decodeColour(images, info.colour_size, info.colour_codec, info.width, info.height, out.bgr))
    return false;
  // Version 3: the depth camera's size (registered depth: the colour size).
  if (!decodeDepth(images + info.colour_size, info.depth_size, info.depth_codec, camera_.depthWidth(),
                   camera_.depthHeight(), out.depth_raw))
    return false;
  has_last_timestamp_ = true;
  last_timestamp_s_ = info.timestamp_s;
  out.sequence = info.sequence;
  out.timestamp_s = info.timestamp_s;
  out.depth_timestamp_s = info.depth_timestamp_s;
  out.depth_factor = info.depth_factor;
  out.t_sensor_ns = monotonicNowNs();  // replay: when it was delivered (frame_source contract)
  return true;
}

Status readRecordingIndex(const std::string& path, std::vector<IndexEntry>* entries) {
  std::FILE* file = nullptr;
  uint64_t size = 0;
  Status st = openFile(path, &file, &size);
  auto readAt = [&](uint64_t offset, std::vector<uint8_t>& dst, std::size_t n) {
    dst.resize(n);
    return fseeko(file, static_cast<off_t>(offset), SEEK_SET) == 0 &&
           std::fread(dst.data(), 1, n, file) == n;
  };
  // Reads and checks the chunk at `offset`, which must be of `type`.
  auto readChunk = [&](uint64_t offset, ChunkType type, std::vector<uint8_t>& bytes) {
    ChunkHeader header;
    return offset >= kFileHeaderSize && offset + kChunkHeaderSize <= size &&
           readAt(offset, bytes, kChunkHeaderSize) && decodeChunkHeader(bytes.data(), &header) &&
           header.type == type &&
           header.payload_size + kChunkHeaderSize + kChunkCrcSize <= size - offset &&
           readAt(offset, bytes, kChunkHeaderSize + header.payload_size + kChunkCrcSize) &&
           chunkCrcMatches(bytes.data(), header.payload_size);
  };
  std::vector<uint8_t> bytes;
  const std::size_t end_chunk_size = kChunkHeaderSize + kEndPayloadSize + kChunkCrcSize;
  if (st.ok() && (size < end_chunk_size || !readChunk(size - end_chunk_size, ChunkType::kEnd, bytes)))
    st = Status::Error(path + ": no valid end chunk (file not closed properly); scan it instead");
  std::vector<std::vector<IndexEntry>> segments;  // newest first
  if (st.ok()) {
    ByteReader end(bytes.data() + kChunkHeaderSize, kEndPayloadSize);
    uint64_t index_offset = end.u64();
    const uint64_t frame_count = end.u64();
    uint64_t total = 0;
    while (st.ok() && index_offset != 0) {
      if (!readChunk(index_offset, ChunkType::kIndex, bytes)) {
        st = Status::Error(path + ": index chunk at byte " + std::to_string(index_offset) +
                           " damaged");
        break;
      }
      ByteReader r(bytes.data() + kChunkHeaderSize, bytes.size() - kChunkHeaderSize - kChunkCrcSize);
      const uint64_t previous = r.u64();
      const uint32_t count = r.u32();
      r.u32();
      if (previous >= index_offset || count > r.remaining() / kIndexEntrySize) {
        st = Status::Error(path + ": index chunk at byte " + std::to_string(index_offset) +
                           " inconsistent");
        break;
      }
      segments.emplace_back(count);
      for (IndexEntry& e : segments.back()) {
        e.sequence = r.u64();
        e.timestamp_s = r.f64();
        e.chunk_offset = r.u64();
      }
      total += count;
      index_offset = previous;
    }
    if (st.ok() && total != frame_count)
      st = Status::Error(path + ": index lists " + std::to_string(total) + " frames, end chunk says " +
                         std::to_string(frame_count));
  }
  if (file) std::fclose(file);
  if (!st.ok()) return st;
  entries->clear();
  for (auto it = segments.rbegin(); it != segments.rend(); ++it)
    entries->insert(entries->end(), it->begin(), it->end());
  return Status::Ok();
}

}  // namespace plumb

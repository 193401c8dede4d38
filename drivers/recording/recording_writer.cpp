#include "drivers/recording/recording_writer.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "drivers/recording/byte_io.h"
#include "drivers/recording/frame_codec.h"

namespace plumb {

Status RecordingWriter::open(const std::string& path, const PinholeCamera& camera,
                             const RecordingWriterOptions& options,
                             std::unique_ptr<RecordingWriter>* out) {
  const std::string problem = camera.validate();
  if (!problem.empty()) return Status::Error(path + ": camera invalid: " + problem);
  if (options.png_compression < 0 || options.png_compression > 9)
    return Status::Error(path + ": png_compression must be 0..9");
  std::unique_ptr<RecordingWriter> writer(new RecordingWriter());
  writer->path_ = path;
  writer->camera_ = camera;
  writer->options_ = options;
  writer->fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (writer->fd_ < 0) return Status::Error(path + ": cannot create: " + std::strerror(errno));
  writer->pending_index_.reserve(options.index_interval_frames);
  encodeFileHeader(camera, writer->chunk_);
  PLUMB_RETURN_IF_ERROR(writer->writeBuffer());
  *out = std::move(writer);
  return Status::Ok();
}

RecordingWriter::~RecordingWriter() {
  const Status st = close();
  if (!st.ok()) std::fprintf(stderr, "plumb: %s\n", st.message().c_str());
}

Status RecordingWriter::append(const RgbdImage& frame) {
  if (fd_ < 0) return Status::Error(path_ + ": append after close");
  if (frame.bgr.type() != CV_8UC3 || frame.bgr.cols != camera_.width ||
      frame.bgr.rows != camera_.height)
    return Status::Error(path_ + ": colour image must be CV_8UC3 " + std::to_string(camera_.width) +
                         "x" + std::to_string(camera_.height));
  // Unregistered depth (a version 3 file) has the depth camera's size, registered depth the colour's.
  if (frame.depth_raw.type() != CV_16UC1 || frame.depth_raw.cols != camera_.depthWidth() ||
      frame.depth_raw.rows != camera_.depthHeight())
    return Status::Error(path_ + ": depth image must be CV_16UC1 " + std::to_string(camera_.depthWidth()) + "x" +
                         std::to_string(camera_.depthHeight()));

  chunk_.clear();
  beginChunk(ChunkType::kFrame, chunk_);
  FrameChunkInfo info;
  info.sequence = frame.sequence;
  info.timestamp_s = frame.timestamp_s;
  info.depth_timestamp_s = frame.depth_timestamp_s;
  info.t_sensor_ns = frame.t_sensor_ns;
  info.width = frame.bgr.cols;
  info.height = frame.bgr.rows;
  info.depth_factor = frame.depth_factor;
  info.colour_codec = options_.colour_codec;
  info.depth_codec = options_.depth_codec;
  const std::size_t info_at = chunk_.size();
  encodeFrameInfo(info, chunk_);  // sizes patched below once the images are encoded
  const std::size_t colour_at = chunk_.size();
  if (!encodeColour(frame.bgr, options_.colour_codec, options_.png_compression, chunk_))
    return Status::Error(path_ + ": colour encoding failed");
  const std::size_t depth_at = chunk_.size();
  if (!encodeDepth(frame.depth_raw, options_.depth_codec, options_.png_compression, chunk_))
    return Status::Error(path_ + ": depth encoding failed");
  ByteWriter patch(chunk_);
  patch.patchU32(info_at + 52, static_cast<uint32_t>(depth_at - colour_at));
  patch.patchU32(info_at + 56, static_cast<uint32_t>(chunk_.size() - depth_at));
  if (chunk_.size() - kChunkHeaderSize > kMaxChunkPayload)
    return Status::Error(path_ + ": frame too large for one chunk");
  endChunk(0, chunk_);

  const uint64_t chunk_offset = bytes_written_;
  PLUMB_RETURN_IF_ERROR(writeBuffer());
  pending_index_.push_back(IndexEntry{frame.sequence, frame.timestamp_s, chunk_offset});
  ++frames_written_;
  if (options_.fsync == FsyncPolicy::kEveryFrame) PLUMB_RETURN_IF_ERROR(sync());
  if (options_.index_interval_frames > 0 &&
      pending_index_.size() >= options_.index_interval_frames) {
    PLUMB_RETURN_IF_ERROR(writeIndex());
    if (options_.fsync != FsyncPolicy::kNever) PLUMB_RETURN_IF_ERROR(sync());
  }
  return Status::Ok();
}

Status RecordingWriter::writeIndex() {
  chunk_.clear();
  beginChunk(ChunkType::kIndex, chunk_);
  ByteWriter w(chunk_);
  w.u64(previous_index_offset_);
  w.u32(static_cast<uint32_t>(pending_index_.size()));
  w.u32(0);
  for (const IndexEntry& e : pending_index_) {
    w.u64(e.sequence);
    w.f64(e.timestamp_s);
    w.u64(e.chunk_offset);
  }
  endChunk(0, chunk_);
  const uint64_t index_offset = bytes_written_;
  PLUMB_RETURN_IF_ERROR(writeBuffer());
  previous_index_offset_ = index_offset;
  pending_index_.clear();
  return Status::Ok();
}

Status RecordingWriter::close() {
  if (fd_ < 0) return Status::Ok();
  Status st = writeIndex();  // always written, possibly empty, so the end chunk has a target
  if (st.ok()) {
    chunk_.clear();
    beginChunk(ChunkType::kEnd, chunk_);
    ByteWriter w(chunk_);
    w.u64(previous_index_offset_);
    w.u64(frames_written_);
    endChunk(0, chunk_);
    st = writeBuffer();
  }
  if (st.ok() && options_.fsync != FsyncPolicy::kNever) st = sync();
  if (::close(fd_) != 0 && st.ok())
    st = Status::Error(path_ + ": close failed: " + std::strerror(errno));
  fd_ = -1;
  return st;
}

Status RecordingWriter::writeBuffer() {
  const uint8_t* p = chunk_.data();
  std::size_t left = chunk_.size();
  while (left > 0) {
    const ssize_t n = ::write(fd_, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return Status::Error(path_ + ": write failed: " + std::strerror(errno));
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  bytes_written_ += chunk_.size();
  return Status::Ok();
}

Status RecordingWriter::sync() {
  if (::fsync(fd_) != 0) return Status::Error(path_ + ": fsync failed: " + std::strerror(errno));
  return Status::Ok();
}

}  // namespace plumb

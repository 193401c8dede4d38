#pragma once
// RecordingWriter: appends RGB-D frames to a .plumbrec file (format: recording_format.h,
// docs/DRIVERS.md). Each frame is assembled in a reused buffer and written with one write() as a
// self-checking chunk, so a power cut leaves at most one partial chunk at the tail, which the
// reader reports as truncated and ignores.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "drivers/recording/recording_format.h"
#include "sensor/camera.h"
#include "sensor/rgbd_image.h"
#include "platform/status.h"

namespace plumb {

enum class FsyncPolicy {
  kNever,       // leave flushing to the OS (fastest; a crash may lose the last seconds)
  kAtIndex,     // fsync after every index chunk and at close
  kEveryFrame,  // fsync after every frame (safest; costs a disk flush per frame)
};

struct RecordingWriterOptions {
  ImageCodec colour_codec = ImageCodec::kPng;  // PNG: ~2-3x smaller than raw, still exact
  ImageCodec depth_codec = ImageCodec::kPng;
  int png_compression = 1;              // zlib level 0..9; 1 is fast and already compresses well
  uint32_t index_interval_frames = 300; // an index chunk every ~10 s at 30 Hz
  FsyncPolicy fsync = FsyncPolicy::kAtIndex;
};

class RecordingWriter {
 public:
  // Creates (truncates) `path` and writes the file header carrying `camera`.
  static Status open(const std::string& path, const PinholeCamera& camera,
                     const RecordingWriterOptions& options, std::unique_ptr<RecordingWriter>* out);
  ~RecordingWriter();  // closes if close() was not called (errors are then only printed)
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  // Frame images must match the camera size: CV_8UC3 bgr, CV_16UC1 depth_raw (of the depth
  // camera's size when the camera has one: the file is then version 3).
  Status append(const RgbdImage& frame);
  // Writes the last index and the end chunk, fsyncs and closes. Idempotent.
  Status close();

  uint64_t framesWritten() const { return frames_written_; }
  uint64_t bytesWritten() const { return bytes_written_; }
  const std::string& path() const { return path_; }

 private:
  RecordingWriter() = default;
  Status writeBuffer();  // writes chunk_ to the file
  Status writeIndex();
  Status sync();

  std::string path_;
  PinholeCamera camera_;
  RecordingWriterOptions options_;
  int fd_ = -1;
  uint64_t frames_written_ = 0;
  uint64_t bytes_written_ = 0;
  uint64_t previous_index_offset_ = 0;  // 0 = no index chunk yet
  std::vector<IndexEntry> pending_index_;  // frames since the last index chunk
  std::vector<uint8_t> chunk_;              // reused chunk assembly buffer
};

}  // namespace plumb

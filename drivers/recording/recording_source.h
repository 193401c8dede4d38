#pragma once
// RecordingSource: replays a .plumbrec file by walking its chunks; it never needs the index.
//
// Damage handling (documented in docs/DRIVERS.md):
//  - a chunk whose header or CRC does not hold is skipped: the reader resynchronises on the next
//    "PLCK" whose header CRC holds, and counts one skipped chunk per damaged region;
//  - bytes at the end that do not form a complete chunk (power cut while writing) are counted as
//    the truncated tail and the replay ends cleanly after the last good frame.
// Nothing of this is an error: the statistics say what was skipped and where.
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "drivers/common/frame_source.h"
#include "drivers/recording/recording_format.h"

namespace plumb {

struct RecordingStats {
  uint64_t frames_read = 0;
  uint64_t chunks_skipped = 0;        // damaged regions skipped (bad CRC, bad header, undecodable)
  uint64_t bytes_skipped = 0;         // bytes inside those regions
  uint64_t index_chunks = 0;          // index chunks passed over
  uint64_t truncated_tail_bytes = 0;  // trailing bytes that are not a complete chunk
  bool end_chunk_seen = false;        // the writer closed the file properly
  std::string last_damage;            // e.g. "chunk at byte 1234: CRC mismatch"
};

class RecordingSource : public FrameSource {
 public:
  static Status open(const std::string& path, std::unique_ptr<RecordingSource>* out);
  ~RecordingSource() override;

  SourceResult next(RgbdImage& out) override;
  const PinholeCamera& camera() const override { return camera_; }
  std::string describe() const override { return "plumbrec:" + path_; }
  const Status& lastError() const override { return last_error_; }

  const RecordingStats& stats() const { return stats_; }
  SourceDamage damage() const override;
  void rewind();
  // Replaces the recorded intrinsics (e.g. a later calibration). The image size must match.
  Status overrideCamera(const PinholeCamera& camera);

 private:
  RecordingSource() = default;
  std::size_t readAt(uint64_t offset, uint8_t* dst, std::size_t n);
  // Offset of the next valid chunk header at or after `from`, or file_size_ when none.
  uint64_t findNextChunk(uint64_t from);
  // Skips the damaged bytes starting at pos_; `why` is recorded in the stats.
  void skipDamage(const char* why);
  bool decodeFrame(const FrameChunkInfo& info, const uint8_t* images, RgbdImage& out);

  std::string path_;
  std::FILE* file_ = nullptr;
  uint64_t file_size_ = 0;
  uint64_t pos_ = 0;  // offset of the next chunk
  std::size_t header_size_ = 0;  // the file header's size (version 2 or 3), where chunks begin
  PinholeCamera camera_;
  RecordingStats stats_;
  bool has_last_timestamp_ = false;
  double last_timestamp_s_ = 0;  // of the last frame delivered: time must increase
  Status last_error_;
  std::vector<uint8_t> chunk_;  // reused: the current chunk's bytes
  std::vector<uint8_t> scan_;   // reused: resynchronisation window
};

// Reads the index chain from the end chunk (fast frame listing without decoding). Fails when the
// file was not closed properly; use RecordingSource to read such a file.
Status readRecordingIndex(const std::string& path, std::vector<IndexEntry>* entries);

}  // namespace plumb

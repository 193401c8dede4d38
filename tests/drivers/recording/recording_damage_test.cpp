// A recording cut at any byte replays exactly the frames written completely before the cut; a
// flipped bit costs exactly the chunk it hit; random corruption never crashes the reader and
// never yields a frame that differs from what was written.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <random>

#include "drivers/recording/byte_io.h"
#include "drivers/recording/crc32.h"
#include "drivers/recording/recording_format.h"
#include "drivers/recording/recording_source.h"
#include "drivers/recording/recording_writer.h"
#include "tests/drivers/device_test_util.h"

namespace plumb {
namespace {

struct WrittenRecording {
  std::vector<uint8_t> bytes;
  std::vector<uint64_t> chunk_ends;  // end offset of every chunk (frames, index, end), ascending
  std::vector<uint64_t> frame_starts;
  std::vector<uint64_t> frame_ends;
  std::vector<RgbdImage> frames;
};

std::vector<uint8_t> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

void writeBytes(const std::string& path, const uint8_t* data, std::size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

WrittenRecording writeRecording(const std::string& path, int frame_count, ImageCodec codec,
                                int width, int height) {
  WrittenRecording rec;
  rec.frames = test::makeNoiseFrames(5, width, height, frame_count);
  RecordingWriterOptions options;
  options.colour_codec = options.depth_codec = codec;
  options.fsync = FsyncPolicy::kNever;
  std::unique_ptr<RecordingWriter> writer;
  EXPECT_TRUE(RecordingWriter::open(path, test::smallCamera(width, height), options, &writer).ok());
  for (const RgbdImage& f : rec.frames) {
    rec.frame_starts.push_back(writer->bytesWritten());
    EXPECT_TRUE(writer->append(f).ok());
    rec.frame_ends.push_back(writer->bytesWritten());
    rec.chunk_ends.push_back(writer->bytesWritten());
  }
  EXPECT_TRUE(writer->close().ok());
  rec.bytes = readBytes(path);
  // close() appends the index chunk and the end chunk (16 + 16 + 4 bytes).
  const uint64_t end_chunk_size = kChunkHeaderSize + kEndPayloadSize + kChunkCrcSize;
  rec.chunk_ends.push_back(rec.bytes.size() - end_chunk_size);
  rec.chunk_ends.push_back(rec.bytes.size());
  return rec;
}

struct ReplayResult {
  bool opened = false;
  std::vector<RgbdImage> frames;
  RecordingStats stats;
};

ReplayResult replay(const std::string& path) {
  ReplayResult result;
  std::unique_ptr<RecordingSource> source;
  if (!RecordingSource::open(path, &source).ok()) return result;
  result.opened = true;
  RgbdImage out;
  for (int guard = 0; guard < 1000; ++guard) {
    const SourceResult r = source->next(out);
    if (r != SourceResult::kFrame) break;
    RgbdImage copy = out;
    copy.bgr = out.bgr.clone();
    copy.depth_raw = out.depth_raw.clone();
    result.frames.push_back(copy);
  }
  result.stats = source->stats();
  return result;
}

bool sameFrame(const RgbdImage& a, const RgbdImage& b) {
  return a.sequence == b.sequence && a.timestamp_s == b.timestamp_s &&
         a.depth_timestamp_s == b.depth_timestamp_s && test::sameImage(a.bgr, b.bgr) &&
         test::sameImage(a.depth_raw, b.depth_raw);
}

void checkTruncation(const WrittenRecording& rec, const std::string& cut_path, std::size_t cut) {
  writeBytes(cut_path, rec.bytes.data(), cut);
  const ReplayResult r = replay(cut_path);
  if (cut < kFileHeaderSize) {
    EXPECT_FALSE(r.opened) << "cut at " << cut;
    return;
  }
  ASSERT_TRUE(r.opened) << "cut at " << cut;
  std::size_t complete_frames = 0;
  while (complete_frames < rec.frame_ends.size() && rec.frame_ends[complete_frames] <= cut)
    ++complete_frames;
  uint64_t last_boundary = kFileHeaderSize;
  for (uint64_t end : rec.chunk_ends)
    if (end <= cut) last_boundary = end;
  ASSERT_EQ(r.frames.size(), complete_frames) << "cut at " << cut;
  for (std::size_t i = 0; i < complete_frames; ++i)
    EXPECT_TRUE(sameFrame(rec.frames[i], r.frames[i])) << "cut at " << cut << ", frame " << i;
  EXPECT_EQ(r.stats.chunks_skipped, 0u) << "cut at " << cut;
  EXPECT_EQ(r.stats.truncated_tail_bytes, cut - last_boundary) << "cut at " << cut;
  EXPECT_EQ(r.stats.end_chunk_seen, cut == rec.bytes.size());
}

TEST(RecordingTruncation, EveryCutOfASmallFileKeepsExactlyTheCompleteFrames) {
  test::ScratchDir dir("cut_all");
  const WrittenRecording rec = writeRecording(dir.file("full.plumbrec"), 3, ImageCodec::kRaw, 6, 4);
  ASSERT_GT(rec.bytes.size(), 300u);
  for (std::size_t cut = 0; cut <= rec.bytes.size(); ++cut)
    checkTruncation(rec, dir.file("cut.plumbrec"), cut);
}

TEST(RecordingTruncation, SeededCutsOfAPngFile) {
  test::ScratchDir dir("cut_png");
  const WrittenRecording rec = writeRecording(dir.file("full.plumbrec"), 4, ImageCodec::kPng, 32, 24);
  std::mt19937 rng(1234);
  std::vector<std::size_t> cuts = {0, kFileHeaderSize, rec.bytes.size()};
  for (uint64_t end : rec.frame_ends) cuts.insert(cuts.end(), {end - 1, end, end + 1});
  for (int i = 0; i < 150; ++i) cuts.push_back(rng() % (rec.bytes.size() + 1));
  for (std::size_t cut : cuts) checkTruncation(rec, dir.file("cut.plumbrec"), cut);
}

TEST(RecordingCorruption, AFlippedBitCostsExactlyTheChunkItHit) {
  test::ScratchDir dir("flip");
  const WrittenRecording rec = writeRecording(dir.file("full.plumbrec"), 5, ImageCodec::kPng, 24, 16);
  std::mt19937 rng(77);
  for (std::size_t hit = 0; hit < rec.frames.size(); ++hit) {
    const uint64_t start = rec.frame_starts[hit], end = rec.frame_ends[hit];
    // The magic, the header CRC, a payload byte at random, and the chunk CRC.
    for (uint64_t offset : {start, start + 13, start + 16 + rng() % (end - start - 20), end - 1}) {
      std::vector<uint8_t> bytes = rec.bytes;
      bytes[offset] ^= static_cast<uint8_t>(1u << (rng() % 8));
      writeBytes(dir.file("flip.plumbrec"), bytes.data(), bytes.size());
      const ReplayResult r = replay(dir.file("flip.plumbrec"));
      ASSERT_TRUE(r.opened);
      ASSERT_EQ(r.frames.size(), rec.frames.size() - 1) << "bit flipped at byte " << offset;
      EXPECT_EQ(r.stats.chunks_skipped, 1u) << "bit flipped at byte " << offset;
      EXPECT_EQ(r.stats.bytes_skipped, end - start) << "bit flipped at byte " << offset;
      EXPECT_TRUE(r.stats.end_chunk_seen);
      EXPECT_NE(r.stats.last_damage.find(std::to_string(start)), std::string::npos)
          << r.stats.last_damage;
      for (std::size_t i = 0, j = 0; i < rec.frames.size(); ++i) {
        if (i == hit) continue;
        EXPECT_TRUE(sameFrame(rec.frames[i], r.frames[j++])) << "frame " << i;
      }
    }
  }
}

TEST(RecordingCorruption, FileHeaderDamageIsAClearError) {
  test::ScratchDir dir("header");
  const WrittenRecording rec = writeRecording(dir.file("full.plumbrec"), 1, ImageCodec::kRaw, 4, 4);
  std::vector<uint8_t> bytes = rec.bytes;
  bytes[40] ^= 0x10;  // inside the camera intrinsics
  writeBytes(dir.file("bad.plumbrec"), bytes.data(), bytes.size());
  std::unique_ptr<RecordingSource> source;
  const Status st = RecordingSource::open(dir.file("bad.plumbrec"), &source);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("CRC"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("bad.plumbrec"), std::string::npos) << st.message();
}

// Seeded fuzz loop: bit flips, byte overwrites, cuts, deleted and duplicated ranges, inserted
// garbage and copies of chunk headers. The reader must never crash or loop, and every frame it
// delivers must be one that was written, bit for bit.
TEST(RecordingCorruption, SeededFuzzNeverCrashesAndNeverInventsFrames) {
  test::ScratchDir dir("fuzz");
  const WrittenRecording rec = writeRecording(dir.file("full.plumbrec"), 4, ImageCodec::kPng, 16, 12);
  std::map<uint64_t, const RgbdImage*> by_sequence;
  for (const RgbdImage& f : rec.frames) by_sequence[f.sequence] = &f;
  std::mt19937 rng(20261122);
  int delivered = 0;
  for (int iteration = 0; iteration < 400; ++iteration) {
    std::vector<uint8_t> bytes = rec.bytes;
    const int mutations = 1 + static_cast<int>(rng() % 4);
    for (int m = 0; m < mutations && !bytes.empty(); ++m) {
      const std::size_t at = rng() % bytes.size();
      const std::size_t len = 1 + rng() % std::min<std::size_t>(64, bytes.size() - at);
      switch (rng() % 6) {
        case 0: bytes[at] ^= static_cast<uint8_t>(1u << (rng() % 8)); break;
        case 1: for (std::size_t i = 0; i < len; ++i) bytes[at + i] = rng() & 0xFF; break;
        case 2: bytes.resize(at); break;
        case 3: bytes.erase(bytes.begin() + at, bytes.begin() + at + len); break;
        case 4: {
          std::vector<uint8_t> copy(bytes.begin() + at, bytes.begin() + at + len);
          bytes.insert(bytes.begin() + rng() % bytes.size(), copy.begin(), copy.end());
          break;
        }
        default: {  // a stray copy of a real chunk header (magic + valid header CRC)
          const uint64_t start = rec.frame_starts[rng() % rec.frame_starts.size()];
          bytes.insert(bytes.begin() + at, rec.bytes.begin() + start,
                       rec.bytes.begin() + start + kChunkHeaderSize);
        }
      }
    }
    writeBytes(dir.file("fuzz.plumbrec"), bytes.data(), bytes.size());
    const ReplayResult r = replay(dir.file("fuzz.plumbrec"));
    for (const RgbdImage& f : r.frames) {
      auto it = by_sequence.find(f.sequence);
      ASSERT_NE(it, by_sequence.end()) << "iteration " << iteration << ": invented sequence";
      EXPECT_TRUE(sameFrame(*it->second, f)) << "iteration " << iteration;
      ++delivered;
    }
  }
  EXPECT_GT(delivered, 0);  // the loop really exercised replay, not only open failures
}

}  // namespace
}  // namespace plumb

namespace plumb {
namespace {

// A header that claims more bytes than the file has left but is otherwise valid (its own CRC
// holds): damage when a valid chunk follows (the later frames are kept), not a power-cut tail.
TEST(RecordingCorruption, AnOversizedChunkHeaderCostsOnlyItsChunk) {
  test::ScratchDir dir("oversize");
  const WrittenRecording rec = writeRecording(dir.file("full.plumbrec"), 5, ImageCodec::kRaw, 24, 16);
  std::vector<uint8_t> bytes = rec.bytes;
  const uint64_t start = rec.frame_starts[1];
  // payload size <- the largest value the format allows, header CRC recomputed.
  std::vector<uint8_t> patched(bytes.begin(), bytes.end());
  ByteWriter w(patched);
  w.patchU32(start + 8, static_cast<uint32_t>(kMaxChunkPayload));
  w.patchU32(start + 12, crc32(patched.data() + start, 12));
  writeBytes(dir.file("oversize.plumbrec"), patched.data(), patched.size());
  const ReplayResult r = replay(dir.file("oversize.plumbrec"));
  ASSERT_TRUE(r.opened);
  EXPECT_EQ(r.frames.size(), rec.frames.size() - 1);
  EXPECT_EQ(r.stats.chunks_skipped, 1u);
  EXPECT_EQ(r.stats.truncated_tail_bytes, 0u) << "reported as a cut tail: " << r.stats.last_damage;
  EXPECT_TRUE(r.stats.end_chunk_seen);
}

// Frames whose timestamps are NaN, repeated or going backwards (CRC intact) are damage: skipped,
// counted and named, never delivered into a trajectory.
TEST(RecordingCorruption, NanRepeatedAndBackwardTimestampsAreSkippedAsDamage) {
  test::ScratchDir dir("time");
  std::vector<RgbdImage> frames = test::makeNoiseFrames(5, 24, 16, 6);
  const double stamps[] = {1.0, std::nan(""), 1.1, 1.1, 1.05, 1.2};
  for (std::size_t i = 0; i < frames.size(); ++i) frames[i].timestamp_s = frames[i].depth_timestamp_s = stamps[i];
  RecordingWriterOptions options;
  options.colour_codec = options.depth_codec = ImageCodec::kRaw;
  options.fsync = FsyncPolicy::kNever;
  std::unique_ptr<RecordingWriter> writer;
  ASSERT_TRUE(RecordingWriter::open(dir.file("t.plumbrec"), test::smallCamera(24, 16), options, &writer).ok());
  for (const RgbdImage& f : frames) ASSERT_TRUE(writer->append(f).ok());
  ASSERT_TRUE(writer->close().ok());
  const ReplayResult r = replay(dir.file("t.plumbrec"));
  ASSERT_TRUE(r.opened);
  ASSERT_EQ(r.frames.size(), 3u);
  EXPECT_EQ(r.frames[0].timestamp_s, 1.0);
  EXPECT_EQ(r.frames[1].timestamp_s, 1.1);
  EXPECT_EQ(r.frames[2].timestamp_s, 1.2);
  EXPECT_EQ(r.stats.chunks_skipped, 3u);
  std::unique_ptr<RecordingSource> source;
  ASSERT_TRUE(RecordingSource::open(dir.file("t.plumbrec"), &source).ok());
  RgbdImage out;
  while (source->next(out) == SourceResult::kFrame) {
  }
  EXPECT_TRUE(source->damage().any());
  EXPECT_EQ(source->damage().regions_skipped, 3u);
}

}  // namespace
}  // namespace plumb

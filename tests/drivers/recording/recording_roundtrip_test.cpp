// Recording round trips: every pixel and timestamp comes back exactly, with both codecs, on
// generated frames and on the shared TUM frames; the index lists every frame.
#include <gtest/gtest.h>

#include <filesystem>

#include "drivers/dataset/camera_presets.h"
#include "drivers/dataset/tum_dataset.h"
#include "drivers/recording/recording_source.h"
#include "drivers/recording/recording_writer.h"
#include "tests/drivers/device_test_util.h"

namespace plumb {
namespace {

using test::makeNoiseFrames;
using test::sameImage;

void writeFrames(const std::string& path, const PinholeCamera& camera,
                 const std::vector<RgbdImage>& frames, const RecordingWriterOptions& options) {
  std::unique_ptr<RecordingWriter> writer;
  ASSERT_TRUE(RecordingWriter::open(path, camera, options, &writer).ok());
  for (const RgbdImage& f : frames) ASSERT_TRUE(writer->append(f).ok());
  ASSERT_TRUE(writer->close().ok());
}

void expectSameFrame(const RgbdImage& expected, const RgbdImage& actual) {
  EXPECT_EQ(expected.sequence, actual.sequence);
  EXPECT_EQ(expected.timestamp_s, actual.timestamp_s);  // exact: stored as binary64
  EXPECT_EQ(expected.depth_timestamp_s, actual.depth_timestamp_s);
  EXPECT_EQ(expected.depth_factor, actual.depth_factor);
  EXPECT_TRUE(sameImage(expected.bgr, actual.bgr)) << "colour of frame " << expected.sequence;
  EXPECT_TRUE(sameImage(expected.depth_raw, actual.depth_raw)) << "depth of frame " << expected.sequence;
}

class RoundTripByCodec : public ::testing::TestWithParam<ImageCodec> {};

TEST_P(RoundTripByCodec, GeneratedFramesComeBackExactly) {
  test::ScratchDir dir("roundtrip");
  const PinholeCamera camera = test::smallCamera(40, 30);
  const auto frames = makeNoiseFrames(11, 40, 30, 7);
  RecordingWriterOptions options;
  options.colour_codec = options.depth_codec = GetParam();
  options.index_interval_frames = 3;  // several index chunks in the file
  writeFrames(dir.file("a.plumbrec"), camera, frames, options);

  std::unique_ptr<RecordingSource> source;
  ASSERT_TRUE(RecordingSource::open(dir.file("a.plumbrec"), &source).ok());
  EXPECT_EQ(source->camera().fx, camera.fx);
  EXPECT_EQ(source->camera().fy, camera.fy);
  EXPECT_EQ(source->camera().k1, camera.k1);
  EXPECT_EQ(source->camera().depth_factor, camera.depth_factor);
  RgbdImage out;
  for (const RgbdImage& f : frames) {
    ASSERT_EQ(source->next(out), SourceResult::kFrame);
    expectSameFrame(f, out);
  }
  EXPECT_EQ(source->next(out), SourceResult::kEndOfStream);
  EXPECT_EQ(source->stats().frames_read, 7u);
  EXPECT_EQ(source->stats().chunks_skipped, 0u);
  EXPECT_EQ(source->stats().truncated_tail_bytes, 0u);
  EXPECT_EQ(source->stats().index_chunks, 3u);  // after frames 3 and 6, and at close
  EXPECT_TRUE(source->stats().end_chunk_seen);

  std::vector<IndexEntry> index;
  ASSERT_TRUE(readRecordingIndex(dir.file("a.plumbrec"), &index).ok());
  ASSERT_EQ(index.size(), frames.size());
  for (std::size_t i = 0; i < index.size(); ++i) {
    EXPECT_EQ(index[i].sequence, frames[i].sequence);
    EXPECT_EQ(index[i].timestamp_s, frames[i].timestamp_s);
  }
}

INSTANTIATE_TEST_SUITE_P(Codecs, RoundTripByCodec,
                         ::testing::Values(ImageCodec::kRaw, ImageCodec::kPng));

TEST(RecordingRoundTrip, ReplayRestartsAfterRewind) {
  test::ScratchDir dir("rewind");
  const auto frames = makeNoiseFrames(3, 16, 12, 2);
  writeFrames(dir.file("r.plumbrec"), test::smallCamera(16, 12), frames, {});
  std::unique_ptr<RecordingSource> source;
  ASSERT_TRUE(RecordingSource::open(dir.file("r.plumbrec"), &source).ok());
  RgbdImage out;
  while (source->next(out) == SourceResult::kFrame) {}
  source->rewind();
  ASSERT_EQ(source->next(out), SourceResult::kFrame);
  expectSameFrame(frames[0], out);
}

TEST(RecordingRoundTrip, WriterRejectsFramesOfTheWrongShape) {
  test::ScratchDir dir("shape");
  std::unique_ptr<RecordingWriter> writer;
  ASSERT_TRUE(RecordingWriter::open(dir.file("s.plumbrec"), test::smallCamera(16, 12), {}, &writer).ok());
  RgbdImage wrong = test::makeNoiseFrame(1, 17, 12, 0);
  const Status st = writer->append(wrong);
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("s.plumbrec"), std::string::npos) << st.message();
}

TEST(RecordingRoundTrip, OpenNamesTheFileWhenItIsNotARecording) {
  test::ScratchDir dir("notrec");
  const std::string path = dir.file("x.plumbrec");
  std::FILE* f = std::fopen(path.c_str(), "wb");
  for (int i = 0; i < 20; ++i) std::fputs("not a recording. ", f);  // longer than a header
  std::fclose(f);
  std::unique_ptr<RecordingSource> source;
  const Status st = RecordingSource::open(path, &source);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find(path), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("PLUMBREC"), std::string::npos) << st.message();
}

TEST(RecordingRoundTrip, SharedTumFramesAreByteExact) {
  const std::string dataset = std::string(PLUMB_DATASETS_DIR) + "/tum_fr1_desk_first9";
  if (!std::filesystem::exists(dataset))
    GTEST_SKIP() << "shared TUM data not found at " << dataset;
  PinholeCamera camera;
  ASSERT_TRUE(cameraFromSpec("tum1", &camera).ok());
  std::unique_ptr<TumDatasetSource> tum;
  const Status opened = TumDatasetSource::open(dataset, camera, &tum);
  ASSERT_TRUE(opened.ok()) << opened.message();
  test::ScratchDir dir("tum");
  std::vector<RgbdImage> frames;
  {
    std::unique_ptr<RecordingWriter> writer;
    ASSERT_TRUE(RecordingWriter::open(dir.file("tum.plumbrec"), camera, {}, &writer).ok());
    RgbdImage frame;
    while (tum->next(frame) == SourceResult::kFrame) {
      ASSERT_TRUE(writer->append(frame).ok());
      RgbdImage copy = frame;
      copy.bgr = frame.bgr.clone();
      copy.depth_raw = frame.depth_raw.clone();
      frames.push_back(copy);
    }
    ASSERT_TRUE(writer->close().ok());
  }
  ASSERT_EQ(frames.size(), 9u);
  std::unique_ptr<RecordingSource> source;
  ASSERT_TRUE(RecordingSource::open(dir.file("tum.plumbrec"), &source).ok());
  RgbdImage out;
  for (const RgbdImage& f : frames) {
    ASSERT_EQ(source->next(out), SourceResult::kFrame);
    expectSameFrame(f, out);
  }
  EXPECT_EQ(source->next(out), SourceResult::kEndOfStream);
  EXPECT_EQ(source->stats().chunks_skipped, 0u);
}

}  // namespace
}  // namespace plumb

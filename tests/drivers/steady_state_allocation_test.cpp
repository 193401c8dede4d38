// Live capture and raw recording must not allocate per frame once running: V4L2 capture with
// pairing and conversion, the supervisor around it, and the .plumbrec writer and reader with the
// raw codec (PNG goes through libpng/zlib, which allocate internally: not held to this).
#include <gtest/gtest.h>

#include "drivers/fault/resilient_source.h"
#include "drivers/recording/recording_source.h"
#include "drivers/recording/recording_writer.h"
#include "drivers/v4l2/v4l2_source.h"
#include "platform/allocation_counter.h"
#include "tests/drivers/device_test_util.h"
#include "tests/drivers/v4l2/fake_v4l2_device.h"

namespace plumb {
namespace {

TEST(SteadyStateAllocations, TheCounterIsLinkedIn) {
  AllocationScope scope;
  std::vector<int> probe(16);  // an allocation the hook must see
  probe[3] = 1;
  EXPECT_GE(scope.count(), 1u);
  EXPECT_EQ(probe[3], 1);
}

TEST(SteadyStateAllocations, SupervisedV4l2CaptureAllocatesNothingPerFrame) {
  test::FakeV4l2Device fake;
  fake.logging = false;
  for (const char* node : {"/dev/video0", "/dev/video1"}) {
    test::FakeV4l2Node n;
    n.width = 64;
    n.height = 48;
    n.bytes_per_line = 128;
    if (std::string(node) == "/dev/video1") n.fourcc = V4L2_PIX_FMT_Z16;
    fake.nodes[node] = n;
  }
  PinholeCamera camera = test::smallCamera(64, 48);
  V4l2SourceOptions options;
  options.depth_device = "/dev/video1";
  std::unique_ptr<V4l2Source> v4l2;
  ASSERT_TRUE(V4l2Source::open(options, camera, fake, &v4l2).ok());
  VirtualClock clock;
  ResilientSource source(std::move(v4l2), {}, clock);
  RgbdImage frame;
  for (int i = 0; i < 3; ++i) ASSERT_EQ(source.next(frame), SourceResult::kFrame);  // warm-up
  AllocationScope scope;
  for (int i = 0; i < 50; ++i) ASSERT_EQ(source.next(frame), SourceResult::kFrame);
  EXPECT_EQ(scope.count(), 0u);
}

TEST(SteadyStateAllocations, RawRecordingWriteAndReplayAllocateNothingPerFrame) {
  test::ScratchDir dir("alloc");
  const std::vector<RgbdImage> frames = test::makeNoiseFrames(4, 64, 48, 40);
  RecordingWriterOptions options;
  options.colour_codec = options.depth_codec = ImageCodec::kRaw;
  options.fsync = FsyncPolicy::kNever;
  options.index_interval_frames = 10;  // index chunks inside the measured span
  std::unique_ptr<RecordingWriter> writer;
  ASSERT_TRUE(RecordingWriter::open(dir.file("a.plumbrec"), test::smallCamera(64, 48), options, &writer).ok());
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(writer->append(frames[i]).ok());
  {
    AllocationScope scope;
    for (int i = 3; i < 40; ++i) ASSERT_TRUE(writer->append(frames[i]).ok());
    EXPECT_EQ(scope.count(), 0u) << "writer";
  }
  ASSERT_TRUE(writer->close().ok());
  std::unique_ptr<RecordingSource> reader;
  ASSERT_TRUE(RecordingSource::open(dir.file("a.plumbrec"), &reader).ok());
  RgbdImage frame;
  for (int i = 0; i < 3; ++i) ASSERT_EQ(reader->next(frame), SourceResult::kFrame);
  AllocationScope scope;
  for (int i = 3; i < 40; ++i) ASSERT_EQ(reader->next(frame), SourceResult::kFrame);
  EXPECT_EQ(scope.count(), 0u) << "reader";
}

}  // namespace
}  // namespace plumb

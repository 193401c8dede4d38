// ViewerSink and RunFeed (viewer/): what `plumb run --serve` adds to the run's threads forwards
// everything unchanged, allocates nothing, never waits, and counts what it could not hand over.
#include "viewer/viewer_sink.h"

#include <gtest/gtest.h>

#include <memory>

#include "platform/allocation_counter.h"
#include "viewer/run_feed.h"

namespace plumb::viewer {
namespace {

// Counts the calls the decorator passes on.
class CountingSink final : public OdometrySink {
 public:
  void onPose(const FrameOutput&) override { ++poses; }
  Status onFrame(const FrameOutput&) override {
    ++frames;
    return Status::Ok();
  }
  Status onFinishedFrame(const FinishedFrame&) override {
    ++finished;
    return fail_finished ? Status::Error("the inner sink's status travels back") : Status::Ok();
  }
  Status onRetiredKeyframe(const RetiredKeyframe&) override {
    ++retired;
    return Status::Ok();
  }
  void onFrameView(const FrameView&) override { ++views; }
  int poses = 0, frames = 0, finished = 0, retired = 0, views = 0;
  bool fail_finished = false;
};

struct Fixture {
  std::unique_ptr<RunFeed> feed = std::make_unique<RunFeed>();
  CountingSink inner;
  ViewerSink sink{inner, *feed};
  std::unique_ptr<LocalMap> map = std::make_unique<LocalMap>();
  cv::Mat image = cv::Mat(480, 640, CV_8UC3, cv::Scalar(10, 20, 30));
  RgbdImage rgbd;
  OdometryStats stats;
  MapCorrection correction;
  FrameOutput output;

  Fixture() { rgbd.bgr = image; }
  void step(uint64_t sequence) {
    output.sequence = sequence;
    output.timestamp_s = 0.1 * double(sequence);
    output.has_pose = true;
    output.state = TrackingState::kOk;
    output.T_world_cam.translation() = Eigen::Vector3d(double(sequence), 0, 0);
    sink.onPose(output);
    (void)sink.onFrame(output);
    FinishedFrame f;
    f.timestamp_s = output.timestamp_s;
    f.valid = true;
    f.T_world_cam = output.T_world_cam;
    (void)sink.onFinishedFrame(f);
    sink.onFrameView(FrameView{output, rgbd, *map, stats, correction});
  }
};

TEST(ViewerSink, ForwardsEveryCallAndItsStatus) {
  Fixture x;
  x.step(1);
  FinishedFrame f;
  x.inner.fail_finished = true;
  EXPECT_FALSE(x.sink.onFinishedFrame(f).ok());
  EXPECT_TRUE(x.sink.onRetiredKeyframe(RetiredKeyframe{}).ok());
  EXPECT_EQ(x.inner.poses, 1);
  EXPECT_EQ(x.inner.frames, 1);
  EXPECT_EQ(x.inner.finished, 2);
  EXPECT_EQ(x.inner.retired, 1);
  EXPECT_EQ(x.inner.views, 1);
  FeedFrame frame;
  ASSERT_TRUE(x.feed->popFrame(&frame));
  EXPECT_EQ(frame.sequence, 1u);
  EXPECT_DOUBLE_EQ(frame.t_world_cam.x(), 1.0);
  FeedFinishedPose pose;
  ASSERT_TRUE(x.feed->popFinishedPose(&pose));
  EXPECT_TRUE(pose.valid);
}

TEST(ViewerSink, AddsNoAllocationPerFrame) {
  Fixture x;
  x.feed->setImageIntervalNs(1);  // an image copy on every frame: the worst case
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(x.map->points.push_back(LocalMapPoint{}));
    ASSERT_TRUE(x.map->keyframes.push_back(LocalMapKeyframe{uint32_t(i + 1), Eigen::Isometry3d::Identity()}));
  }
  x.step(0);  // warm-up
  AllocationScope scope;
  for (uint64_t i = 1; i < 200; ++i) {
    x.map->version = i / 10;  // the map changes every 10 frames: a copy each time
    if (i % 50 == 0) {
      ++x.stats.loop_corrections_applied;
      x.correction.loop_candidate_id = 3;
    }
    x.step(i);
  }
  EXPECT_EQ(scope.count(), 0u);
}

TEST(ViewerSink, CopiesTheMapWhenItsVersionChangesAndLoopsWhenOneIsApplied) {
  Fixture x;
  ASSERT_TRUE(x.map->points.push_back(LocalMapPoint{}));
  x.map->points[0].P_world = Eigen::Vector3d(1, 2, 3);
  LocalMapLine line;
  line.start_world = Eigen::Vector3d(0, 0, 1);
  line.end_world = Eigen::Vector3d(0, 1, 1);
  ASSERT_TRUE(x.map->lines.push_back(line));
  x.map->version = 7;
  x.stats.loop_corrections_applied = 1;
  x.correction.keyframe_id = 50;
  x.correction.loop_candidate_id = 4;
  x.correction.T_world_cam.translation() = Eigen::Vector3d(5, 0, 0);
  x.correction.T_world_candidate.translation() = Eigen::Vector3d(0.1, 0, 0);
  x.step(3);
  uint64_t version = 0;
  const FeedMap* map = x.feed->latestMap(&version);
  ASSERT_NE(map, nullptr);
  EXPECT_EQ(version, 7u);
  ASSERT_EQ(map->point_count, 1u);
  EXPECT_EQ(map->points_world[0], Eigen::Vector3f(1, 2, 3));
  ASSERT_EQ(map->line_count, 1u);
  EXPECT_EQ(map->lines_world[0].end, Eigen::Vector3f(0, 1, 1));
  FeedLoop loop;
  ASSERT_TRUE(x.feed->popLoop(&loop));
  EXPECT_EQ(loop.query_id, 50u);
  EXPECT_EQ(loop.candidate_id, 4u);
  EXPECT_DOUBLE_EQ(loop.query_position.x(), 5.0);
  EXPECT_FALSE(x.feed->popLoop(&loop));  // one loop, reported once
  x.step(4);
  EXPECT_FALSE(x.feed->popLoop(&loop));
}

TEST(RunFeed, AFullRingDropsAndCountsInsteadOfWaiting) {
  auto feed = std::make_unique<RunFeed>();
  FeedFrame f;
  for (std::size_t i = 0; i < RunFeed::kFrameRingCapacity + 5; ++i) {
    f.sequence = i;
    feed->pushFrame(f);
  }
  EXPECT_EQ(feed->recordsDropped(), 5u);
  FeedFrame out;
  ASSERT_TRUE(feed->popFrame(&out));
  EXPECT_EQ(out.sequence, 0u);  // the oldest stay; the newest were dropped
}

TEST(RunFeed, LatencyOfTheTrackThreadReachesTheFrame) {
  auto feed = std::make_unique<RunFeed>();
  feed->recordLatency(42, 5'000'000);
  FeedFrame f;
  f.sequence = 42;
  feed->pushFrame(f);
  f.sequence = 43;  // no latency recorded for it
  feed->pushFrame(f);
  FeedFrame out;
  ASSERT_TRUE(feed->popFrame(&out));
  EXPECT_DOUBLE_EQ(out.latency_ms, 5.0);
  ASSERT_TRUE(feed->popFrame(&out));
  EXPECT_LT(out.latency_ms, 0.0);
}

TEST(DownscaleInto, BoxAveragesByTheSmallestFittingFactor) {
  auto image = std::make_unique<FeedImage>();
  cv::Mat vga(480, 640, CV_8UC3, cv::Scalar(0, 0, 0));
  vga.at<cv::Vec3b>(0, 0) = cv::Vec3b(100, 40, 8);  // one pixel of the first 2x2 block
  ASSERT_TRUE(downscaleInto(vga, image.get()));
  EXPECT_EQ(image->width, 320);
  EXPECT_EQ(image->height, 240);
  EXPECT_EQ(image->bgr[0], 25);  // (100 + 0 + 0 + 0) / 4
  EXPECT_EQ(image->bgr[1], 10);
  EXPECT_EQ(image->bgr[2], 2);
  cv::Mat hd(720, 1280, CV_8UC3, cv::Scalar(1, 2, 3));
  ASSERT_TRUE(downscaleInto(hd, image.get()));
  EXPECT_EQ(image->width, 320);
  EXPECT_EQ(image->height, 180);
  EXPECT_EQ(image->bgr[3 * 319 + 2], 3);
  EXPECT_FALSE(downscaleInto(cv::Mat(10, 10, CV_8UC1), image.get()));
  EXPECT_FALSE(downscaleInto(cv::Mat(), image.get()));
}

}  // namespace
}  // namespace plumb::viewer

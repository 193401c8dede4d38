#pragma once
// RunFeed: the one hand-off from a running odometry to the viewer's server thread
// (docs/VIEWER.md). Everything is allocated in the constructor; the run's threads only copy into
// it and never wait:
//
//   track thread  (onPose)       -> latency_[sequence % kLatencySlots]         sensor-to-pose time
//   map thread    (onFrame)      -> frames_   SpscRing<FeedFrame>              every frame
//   map thread    (onFinished..) -> finished_ SpscRing<FeedFinishedPose>       the output trajectory
//   map thread    (onFrameView)  -> map_      LatestSnapshot<FeedMap>          when the map changed
//                                -> image_    LatestSnapshot<FeedImage>        when one is wanted
//                                -> loops_    SpscRing<FeedLoop>               per accepted loop
//   server thread                <- all of the above (pop / acquireLatest), on its own clock
//
// A full ring drops the record and counts it (the server thread fell ~2 minutes behind): the run
// never waits for a viewer. Snapshots hold only the newest version, so a slow server thread
// skips versions instead of queueing them.
#include <array>
#include <atomic>
#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pipeline/odometry/map_capacities.h"
#include "pipeline/odometry/tracking_state.h"
#include "runtime/latest_snapshot.h"
#include "runtime/spsc_ring.h"

namespace plumb::viewer {

// A frame as the viewer shows it, as tracked (before local BA refines it).
struct FeedFrame {
  uint64_t sequence = 0;
  double timestamp_s = 0;
  TrackingState state = TrackingState::kNotInitialized;
  bool has_pose = false;
  bool keyframe = false;
  bool dropped = false;  // real-time mode dropped it: nothing else is set
  bool relocalized = false;
  bool new_map = false;
  Eigen::Vector3d t_world_cam = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_world_cam = Eigen::Quaterniond::Identity();
  int point_inliers = 0, line_inliers = 0, landmark_inliers = 0;
  double latency_ms = -1;  // sensor time to pose known (track done); -1: not measured
  double extract_ms = 0, track_ms = 0, map_ms = 0;
};

// A frame of the output trajectory (what the TUM file gets, same order, same values).
struct FeedFinishedPose {
  double timestamp_s = 0;
  bool valid = false;
  bool dropped = false;
  Eigen::Vector3d t_world_cam = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_world_cam = Eigen::Quaterniond::Identity();
};

struct FeedKeyframe {
  uint32_t id = 0;
  Eigen::Vector3f t_world_cam = Eigen::Vector3f::Zero();
  Eigen::Quaternionf q_world_cam = Eigen::Quaternionf::Identity();
};

struct FeedLine {
  Eigen::Vector3f start = Eigen::Vector3f::Zero();
  Eigen::Vector3f end = Eigen::Vector3f::Zero();
};

// The local map (pipeline/odometry/local_map.h) reduced to what is drawn, in floats.
struct FeedMap {
  uint64_t frame_sequence = 0;
  double timestamp_s = 0;
  std::size_t point_count = 0, line_count = 0, keyframe_count = 0;
  std::array<Eigen::Vector3f, kMaxLocalMapPoints> points_world;
  std::array<FeedLine, kMaxLocalMapLines> lines_world;
  std::array<FeedKeyframe, kMaxMapKeyframes> keyframes;
};

// The colour image, box-downscaled by an integer factor to at most kMaxWidth x kMaxHeight.
struct FeedImage {
  static constexpr int kMaxWidth = 320, kMaxHeight = 240;
  uint64_t sequence = 0;
  double timestamp_s = 0;
  int width = 0, height = 0;
  std::array<uint8_t, kMaxWidth * kMaxHeight * 3> bgr;  // rows of width * 3 bytes, packed
};

// An accepted loop: the query keyframe and the old keyframe it was matched to, optimised poses.
struct FeedLoop {
  double timestamp_s = 0;
  uint32_t query_id = 0, candidate_id = 0;
  Eigen::Vector3d query_position = Eigen::Vector3d::Zero();
  Eigen::Vector3d candidate_position = Eigen::Vector3d::Zero();
};

class RunFeed {
 public:
  static constexpr std::size_t kFrameRingCapacity = 4096;  // ~2 min at 30 Hz
  static constexpr std::size_t kLoopRingCapacity = 64;
  static constexpr std::size_t kLatencySlots = 128;        // > the runner's 64 slots at most

  RunFeed() = default;
  RunFeed(const RunFeed&) = delete;
  RunFeed& operator=(const RunFeed&) = delete;

  // Track thread.
  void recordLatency(uint64_t sequence, int64_t latency_ns);
  // Map thread (and, at the end of the run, the thread that called runOdometry).
  void pushFrame(const FeedFrame& frame);           // latency_ms filled from recordLatency
  void pushFinishedPose(const FeedFinishedPose& pose);
  void pushLoop(const FeedLoop& loop);
  FeedMap& mapWriteBuffer() { return map_.writeBuffer(); }
  void publishMap(uint64_t version) { map_.publish(version); }
  FeedImage& imageWriteBuffer() { return image_.writeBuffer(); }
  void publishImage(uint64_t version) { image_.publish(version); }
  // Image copies cost the map thread ~0.1 ms; the server asks for them only while someone
  // watches, at most every image_interval_ns (0: none wanted).
  int64_t imageIntervalNs() const { return image_interval_ns_.load(std::memory_order_relaxed); }

  // Server thread.
  bool popFrame(FeedFrame* frame) { return frames_.try_pop(*frame); }
  bool popFinishedPose(FeedFinishedPose* pose) { return finished_.try_pop(*pose); }
  bool popLoop(FeedLoop* loop) { return loops_.try_pop(*loop); }
  const FeedMap* latestMap(uint64_t* version) { return map_.acquireLatest(version); }
  const FeedImage* latestImage(uint64_t* version) { return image_.acquireLatest(version); }
  void setImageIntervalNs(int64_t ns) { image_interval_ns_.store(ns, std::memory_order_relaxed); }

  // Records the rings could not take (the server thread was that far behind).
  uint64_t recordsDropped() const { return records_dropped_.load(std::memory_order_relaxed); }

 private:
  struct LatencySlot {
    std::atomic<uint64_t> sequence{UINT64_MAX};
    std::atomic<int64_t> latency_ns{-1};
  };
  std::array<LatencySlot, kLatencySlots> latency_{};
  runtime::SpscRing<FeedFrame> frames_{kFrameRingCapacity};
  runtime::SpscRing<FeedFinishedPose> finished_{kFrameRingCapacity};
  runtime::SpscRing<FeedLoop> loops_{kLoopRingCapacity};
  runtime::LatestSnapshot<FeedMap> map_;
  runtime::LatestSnapshot<FeedImage> image_;
  std::atomic<int64_t> image_interval_ns_{0};
  std::atomic<uint64_t> records_dropped_{0};
};

}  // namespace plumb::viewer

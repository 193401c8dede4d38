#pragma once
// OdometrySystem: the odometry as two sides that run on the track and map stages of the one runner
// (pipeline/run/run_session.h); extraction is the extract stage's own FeatureExtractor.
//
//   trackFeatures (tracking side): installs the newest LocalMap snapshot the mapping side published
//     (runtime::LatestSnapshot, newer versions only), then one step of a four-phase state machine
//     (TrackingPhase: start a map / relocalize into a loaded map / relocalize when lost / track)
//     and fills a TrackedFrame (pose, reference keyframe, keyframe request) that travels with the
//     frame to
//   mapFrame (mapping side, frame order): LocalMapper::insertKeyframe + local BA for a request (a
//     new map or segment too: the tracking side only asks for it), publishes the new snapshot,
//     updates the relocalizer, statistics and the output trajectory.
//   lost -> Relocalizer (stored keyframes) -> Tracker::resetAt; still lost after M frames -> a new
//   map segment is requested from the current frame at the last known pose (the trajectory
//   continues).
//
// Each side's state is its own struct (TrackingSide, MappingSide) and only the mapping side calls
// the mapper. What the sides share: the snapshot channel (mapping -> tracking), a counter of
// finished keyframe requests, and the relocalizer, which the mapping side writes and the tracking
// side reads only to relocalize, after MapperFence::waitForMapper() (pipeline/odometry/
// mapper_fence.h) has seen every earlier frame mapped, so the two threads never use it at the same
// time.
// Which map a frame is tracked against (syncWithMapping): in the deterministic and fast schedules
// the map update a keyframe request of frame k asked for is used from frame k +
// SystemOptions::map_lag_frames on (a new map: from k + 1), the fast schedule waiting there for the
// map stage if it is behind, so both schedules track every frame against the same map and write the
// same bytes. With split updates (SystemOptions::refine_lag_frames M >= 1, an option) that update
// comes in two parts, each at a fixed frame: the fresh map (keyframe k and its new landmarks,
// before local BA) from k + 1, the refined map (after k's local BA and loop closing) from
// k + 1 + M, unless a later request's fresh map, which contains it, arrives first; fast mode's
// tracker then tracks k + 1 .. k + M while the map stage runs the BA. Real time tracks against the
// newest snapshot published so far, at most
// fence->maxFramesAhead() frames past a keyframe it asked for. While a keyframe request is pending
// the tracker makes no keyframe decision (ORB-SLAM's "local mapping busy"): it would judge against
// a map that lacks the pending keyframe.
// Output: finished frames (reference-keyframe relative, see OdometryTrajectory) and retired
// keyframes with their covariance, drained on the mapping side.
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "sensor/camera.h"
#include "pipeline/frontend/frame_features.h"
#include "pipeline/odometry/keyframe_request.h"
#include "pipeline/odometry/local_mapper.h"
#include "pipeline/odometry/map_correction.h"
#include "pipeline/odometry/mapper_fence.h"
#include "pipeline/odometry/odometry_options.h"
#include "pipeline/odometry/odometry_stats.h"
#include "pipeline/odometry/odometry_trajectory.h"
#include "pipeline/odometry/relocalizer.h"
#include "pipeline/odometry/tracker.h"
#include "platform/status.h"
#include "runtime/latest_snapshot.h"

namespace plumb {

struct FrameOutput {
  uint64_t sequence = 0;
  double timestamp_s = 0;
  TrackingState state = TrackingState::kNotInitialized;
  bool has_pose = false;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();  // as tracked
  bool keyframe = false;
  bool relocalized = false;
  bool new_map = false;
  // The pose is the first after a loop correction moved the map (docs/LOOP.md "What the robot
  // receives"): the trajectory jumps here, MAVLink announces it with reset_counter.
  bool loop_corrected = false;
  bool dropped = false;  // mapDroppedFrame(): the runtime dropped this frame, nothing else is set
  TrackResult track;
  InsertResult insert;
  double extract_ms = 0, track_ms = 0, map_ms = 0;
  double register_ms = 0;   // depth registration (unregistered depth cameras only; 0 otherwise)
  int64_t t_sensor_ns = 0;  // host monotonic time the frame was captured (set by the runner)
};

// What tracking hands to mapping for one frame. Large (the request holds a copy of the features),
// so a staged runtime allocates one per frame slot, once.
struct TrackedFrame {
  FrameOutput output;            // tracking's part: state, pose, flags, track result, track_ms
  uint32_t reference_id = 0;     // keyframe the output trajectory expresses the pose against
  Eigen::Isometry3d T_ref_cam = Eigen::Isometry3d::Identity();
  bool map_keyframe = false;     // `request` is to be inserted by mapFrame()
  bool relocalization_attempted = false;
  KeyframeRequest request;
};

struct SystemOptions {
  OdometryOptions odometry;
  // Output delay of the reference-keyframe-relative trajectory (frames); 0 = poses as tracked.
  int output_delay_frames = 60;
  // Map updates reach tracking at a fixed lag (docs/RUNTIME.md "Map updates at a fixed lag"): the
  // LocalMap snapshot the mapping side makes from frame k's keyframe request is tracked against
  // from frame k + map_lag_frames on, in the deterministic and fast schedules alike, so both write
  // the same bytes; until then the request is pending and the tracker makes no keyframe decision.
  // 1 (default) = from the next frame: fast mode then waits for each keyframe's mapping before
  // the next frame. L > 1 lets it track L - 1 frames meanwhile, but costs accuracy (low texture
  // with noise: ATE 3.3x at L = 3; docs/RUNTIME.md "Map updates at a fixed lag"). A new map (first
  // frame, new segment) is used from the next frame on whatever the lag. Real-time mode tracks on
  // the newest snapshot instead (OdometryRunOptions::max_frames_ahead_of_mapper).
  int map_lag_frames = kDefaultMapLagFrames;
  static constexpr int kDefaultMapLagFrames = 1;
  static constexpr int kMaxMapLagFrames = 16;
  // Split map updates (docs/RUNTIME.md "Map updates at a fixed lag"), M: the update frame k asked
  // for reaches tracking in two parts, at fixed frames in the deterministic and fast schedules
  // alike (so both write the same bytes): the fresh map (keyframe k inserted at its tracked pose,
  // its new points and line samples at their back-projected positions, before local BA) from frame
  // k + 1 on, and the map after k's local BA (and loop closing) from frame k + 1 + M on, or from
  // the next request's fresh map if that comes first (it contains the BA: the map stage works in
  // frame order). The tracker thus has the newest keyframe's landmarks at once, and fast mode tracks
  // frames k + 1 .. k + M while the map stage runs the BA instead of waiting for it. 0 = one update
  // after the BA, from k + map_lag_frames (the behaviour before the split). M >= 1 needs
  // map_lag_frames = 1. Real time always uses the whole update (newest snapshot).
  int refine_lag_frames = kDefaultRefineLagFrames;
  // 0 by default: measured, the split costs accuracy (head250 ATE +9 % on average over six start
  // frames at M = 1) beyond the 3 % the speed-up (fast 1.9x lock-step instead of ~1.7x) may cost.
  static constexpr int kDefaultRefineLagFrames = 0;
  static constexpr int kMaxRefineLagFrames = 16;
  bool splitMapUpdates() const { return refine_lag_frames > 0; }
};

// Every option of the system in one place; validated once, where the system is built.
Status validate(const SystemOptions& options);

class OdometrySystem {
 public:
  // Refuses options that validate() rejects and a camera that cannot be used, with a message.
  static Status create(const PinholeCamera& camera, const SystemOptions& options,
                       std::unique_ptr<OdometrySystem>* out);
  ~OdometrySystem();
  OdometrySystem(const OdometrySystem&) = delete;
  OdometrySystem& operator=(const OdometrySystem&) = delete;

  const PinholeCamera& camera() const { return camera_; }
  const SystemOptions& options() const { return options_; }

  // A loaded map (--load-map, docs/LOOP.md "Map files"), before the first frame: the relocalizer
  // gets the map's keyframes (addLoadedKeyframe, in its world frame), and beginInLoadedMap() puts
  // the system in the "relocalize into the loaded map" state: every frame is relocalized against
  // those keyframes (no pose, written `# <t> lost`, until one succeeds; no new map is started
  // meanwhile), and the first that succeeds starts the local map at its relocalized pose, so
  // tracking continues in the loaded map's frame. New keyframes get ids from `first_new_id` on
  // (> every loaded id).
  void addLoadedKeyframe(uint32_t keyframe_id, const Eigen::Isometry3d& T_world_cam, std::size_t n,
                         const Descriptor256* descriptors, const Eigen::Vector3f* P_cam);
  void beginInLoadedMap(uint32_t first_new_id);

  // Tracking side. fence may be nullptr (never waits).
  void trackFeatures(const FrameFeatures& features, uint64_t sequence, double timestamp_s, MapperFence* fence,
                     TrackedFrame* out);

  // Mapping side (mapFrame's thread) from here on. fence (may be nullptr) hears when a split
  // update's fresh map is written (MapperFence::insertionPublished) and says the schedule.
  const FrameOutput& mapFrame(const TrackedFrame& tracked, MapperFence* fence = nullptr);
  // A frame the runtime dropped (real-time replay, no free slot) takes its place in the output
  // trajectory (FinishedFrame::dropped); call in frame order between mapFrame() calls.
  const FrameOutput& mapDroppedFrame(uint64_t sequence, double timestamp_s);
  // Frames whose output pose is final, oldest first; fn(const FinishedFrame&). end_of_run: every
  // frame still held back for refinement is final now (resolved against the map as it is).
  template <typename Fn>
  void drainFinishedFrames(Fn fn, bool end_of_run = false) {
    if (end_of_run) {
      mapping_.trajectory.flushAll(mapping_.mapper->localMap(), fn);
    } else {
      mapping_.trajectory.popReady(mapping_.mapper->localMap(), fn);
    }
  }
  // End of the run, after the last drainFinishedFrames(fn, true): every keyframe leaves the map.
  void retireAllKeyframes() { mapping_.mapper->retireAll(); }
  // Retired keyframes (final pose + covariance); fn(const RetiredKeyframe&).
  template <typename Fn>
  void drainRetiredKeyframes(Fn fn) {
    for (const auto& kf : mapping_.mapper->retired()) fn(kf);
    mapping_.mapper->clearRetired();
  }
  // Loop closing's corrections reach the mapping side through this channel (writer: the loop
  // stage; reader: the mapping side). mapFrame() applies the newest unapplied one before anything
  // else (docs/LOOP.md "Correction"); applyLoopCorrection() does the same at the end of a run.
  runtime::LatestSnapshot<MapCorrection>& loopCorrections() { return *corrections_; }
  bool applyLoopCorrection();
  // Mapping side: the newest correction applyLoopCorrection() applied (a copy; keyframe_id 0
  // before the first). Viewers draw loop edges from it.
  const MapCorrection& lastLoopCorrection() const { return mapping_.last_correction; }
  // The rigid motion each applied correction moved the map by, in order: entry e - 1 takes loop
  // epoch e - 1 to epoch e (FinishedFrame::loop_epoch). The first kMaxRecordedCorrections are kept
  // (reserved at construction); later ones are counted in stats only.
  static constexpr std::size_t kMaxRecordedCorrections = 512;
  const std::vector<Eigen::Isometry3d>& appliedCorrections() const { return mapping_.applied_corrections; }
  // The mapper, read by the mapping side's own thread (loop records).
  const LocalMapper& mapper() const { return *mapping_.mapper; }
  const OdometryStats& stats() const { return mapping_.stats; }
  // Tracking side: how often tracking waited for a lagging mapper (MapperFence::maxFramesAhead).
  uint64_t mapperWaits() const { return tracking_.mapper_waits; }
  const MapperStats& mapperStats() const { return mapping_.mapper->stats(); }
  MapCounts mapCounts() const { return mapping_.mapper->map().counts(); }

 private:
  OdometrySystem(const PinholeCamera& camera, const SystemOptions& options);

  // What the tracking side does with the next frame.
  enum class TrackingPhase : uint8_t {
    kStartMap,                 // no map yet: the first frame with enough depth asks for one
    kRelocalizeIntoLoadedMap,  // beginInLoadedMap(): relocalize against the loaded keyframes only
    kRelocalize,               // lost: relocalize; after M failures ask for a new map segment
    kTrack,                    // track against the local map snapshot
  };
  // The tracking thread's state.
  struct TrackingSide {
    std::unique_ptr<Tracker> tracker;
    TrackingPhase phase = TrackingPhase::kStartMap;
    bool new_map_requested = false;  // the previous frame asked for a new map: adopt it next
    int lost_streak = 0;
    Eigen::Isometry3d T_world_last_good = Eigen::Isometry3d::Identity();
    uint64_t frames = 0;             // frames tracked (during trackFeatures: the current one + 1)
    // Fixed lag: the map update a keyframe request asked for, not in use yet (split updates: its
    // fresh map).
    bool update_pending = false;
    bool update_new_map = false;     // it starts a new map
    uint64_t update_frame = 0;       // the frame (index) that asked for it
    uint64_t update_due = 0;         // the first frame tracked against it
    // Split updates: the refined map of the newest fresh map installed, not in use yet.
    bool refinement_pending = false;
    uint64_t refinement_frame = 0;   // the frame that asked for the update
    uint64_t refinement_due = 0;     // the first frame tracked against it
    uint64_t keyframe_requests = 0;  // handed to mapFrame()
    int frames_since_request = 0;    // frames tracked while the newest request was pending
    uint64_t mapper_waits = 0;       // times the bound above made tracking wait
    uint64_t loop_corrections_seen = 0;  // of the map segment the tracker follows
    bool loop_correction_unannounced = false;  // installed, no pose published since
  };
  // The mapping thread's state.
  struct MappingSide {
    std::unique_ptr<LocalMapper> mapper;
    OdometryTrajectory trajectory;
    OdometryStats stats;
    FrameOutput output;
    uint64_t correction_version = 0;  // newest loop correction seen (0: none)
    MapCorrection last_correction;    // newest one applied
    std::vector<Eigen::Isometry3d> applied_corrections;  // appliedCorrections()
    explicit MappingSide(int delay_frames) : trajectory(delay_frames) {
      applied_corrections.reserve(kMaxRecordedCorrections);
    }
  };

  // Tracking side. syncWithMapping: the schedule's part (waits, the newest snapshot); returns
  // whether a keyframe request is still with the mapper. The rest is the state machine.
  bool syncWithMapping(MapperFence* fence);
  bool syncWithNewestSnapshot(MapperFence& fence);
  void installDueUpdate(MapperFence* fence);
  void expectMapUpdate(int lag_frames, bool new_map);
  void installNewestSnapshot();
  void installSnapshot(const LocalMap& snapshot);
  bool canStartMap(const FrameFeatures& features) const;
  void requestNewMap(const FrameFeatures& features, uint64_t sequence, double timestamp_s,
                     const Eigen::Isometry3d& T_world_cam, TrackedFrame* out);
  void trackAgainstMap(const FrameFeatures& features, uint64_t sequence, double timestamp_s, bool request_pending,
                       MapperFence* fence, TrackedFrame* out);
  void tryRelocalize(const FrameFeatures& features, MapperFence* fence, TrackedFrame* out);
  void relocalizeOrStartSegment(const FrameFeatures& features, uint64_t sequence, double timestamp_s,
                                MapperFence* fence, TrackedFrame* out);
  void relocalizeIntoLoadedMap(const FrameFeatures& features, uint64_t sequence, double timestamp_s,
                               MapperFence* fence, TrackedFrame* out);
  // Mapping side. split: the fresh map first (fence->insertionPublished()), then the local BA.
  void insertKeyframe(const KeyframeRequest& request, bool split, MapperFence* fence);
  void recordOutput(const TrackedFrame& tracked);

  const PinholeCamera camera_;
  const SystemOptions options_;
  TrackingSide tracking_;
  MappingSide mapping_;
  // Shared, see the header comment: snapshots mapping -> tracking (triple buffer), finished
  // keyframe requests (release after the snapshot is published), and the relocalizer (written by
  // the mapping side, used by the tracking side only behind the fence).
  std::unique_ptr<runtime::LatestSnapshot<LocalMap>> snapshots_;
  // Split updates only: the fresh map of the newest keyframe request. One buffer is enough: the
  // mapping side writes it while mapping request frame k (then MapperFence::insertionPublished),
  // the tracking side copies it while tracking frame k + 1, and the next write is for a request
  // of frame k + 1 or later, which reaches the map stage only after that frame was tracked.
  std::unique_ptr<LocalMap> fresh_map_;
  std::atomic<uint64_t> keyframe_requests_done_{0};
  std::unique_ptr<Relocalizer> relocalizer_;
  std::unique_ptr<runtime::LatestSnapshot<MapCorrection>> corrections_;
};

}  // namespace plumb

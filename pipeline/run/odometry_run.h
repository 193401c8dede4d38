#pragma once
// runOdometry(): THE frame loop of plumb, and the one place a run is composed: capture -> system
// -> RunSession (pipeline/run/run_session.h) -> runtime::StageRunner. Every way of running the
// odometry over a source (`plumb run`, `plumb demo`, the API's runSource, the Python module's
// run(), the system tests, the benchmarks, and every mode) calls it with its FrameCapture (a
// FrameSource wrapped by drivers/common/source_capture.h); the push-style API steps the same
// RunSession itself.
//
//   capture (FrameCapture: a sensor or replay, prepared ahead)
//     -> extract (FeatureExtractor, own per stage)          pipeline/run/odometry_stages.h
//     -> track   (OdometrySystem tracking side)
//     -> map     (OdometrySystem mapping side: keyframe, local BA, output trajectory -> sink)
//          \__ LocalMap snapshots back to track through the system's snapshot channel __/
//
// The stages are runtime::Stage objects run by runtime::StageRunner. runtime::RunMode picks the
// schedule, never the stages:
//   deterministic: lock-step on the calling thread, one frame through all stages before the next
//     is read. This IS the single-threaded program: every frame sees exactly the map the previous
//     frames left, so the output is byte-identical run after run.
//   fast: a thread per stage over SPSC rings, capture and extract working ahead; the map update a
//     keyframe request of frame k asked for is used from frame k + SystemOptions::map_lag_frames on
//     as in lock-step (the tracker waits there if the map stage is behind; max_frames_ahead_of_mapper
//     0) and the loop stage runs on the map stage's thread: every frame is tracked against exactly
//     the map lock-step would have, so the output is the deterministic output, byte for byte,
//     however loaded the CPU (only the speed changes). Throughput comes from extraction
//     overlapping track + map, and tracking overlapping the map stage for the lag's frames.
//   realtime: a thread per stage; latency first: the tracker may run up to 4 frames past a pending
//     keyframe on the newest published snapshot (timing dependent), the loop stage has its own
//     thread. Paces the capture to the recorded timestamps and drops (and counts, and writes as
//     `# <t> dropped`) a frame that finds no free slot.
// The sink hears about every frame in frame order, on the map stage's thread. At the end (input
// ended, max_frames, a stop request or an error) the session is finished: every pose held back for
// refinement is delivered to the sink, so a stop or a read error keeps what was computed.
#include <atomic>
#include <cstdint>
#include <vector>

#include "pipeline/loop/loop_closer.h"
#include "pipeline/loop/saved_map.h"
#include "pipeline/odometry/odometry_system.h"
#include "platform/status.h"
#include "runtime/run_options.h"
#include "runtime/run_report.h"
#include "runtime/trace_log.h"
#include "sensor/frame_capture.h"

namespace plumb {

// What OdometrySink::onFrameView shows of a frame after mapping.
struct FrameView {
  const FrameOutput& output;   // the frame, as onFrame had it
  const RgbdImage& image;      // its colour and depth images, as captured
  const LocalMap& local_map;   // the mapping side's local map now (LocalMap::version: changed when)
  const OdometryStats& stats;  // the mapping side's counters (loop_corrections_applied, ...)
  // The newest loop correction the mapping side applied (valid when stats.loop_corrections_applied
  // > 0): a viewer draws the loop edge from it.
  const MapCorrection& last_loop_correction;
};

// Where a run's results go. Called on the map stage's thread, in frame order.
class OdometrySink {
 public:
  virtual ~OdometrySink() = default;
  // Once, when everything has been checked and built and before the first frame (open files here:
  // a run refused for its options or camera leaves none). The system may be read from the map
  // stage's callbacks (map counts, statistics).
  virtual Status begin(const OdometrySystem&) { return Status::Ok(); }
  // The pose of a frame as soon as tracking has it, on the TRACK stage's thread, in frame order
  // (what a robot's controller wants, before mapping refines anything). Must not block: it is on
  // the latency path. Not called for dropped frames.
  virtual void onPose(const FrameOutput&) {}
  // Every frame after mapping (FrameOutput::dropped for a frame real-time mode dropped).
  virtual Status onFrame(const FrameOutput&) { return Status::Ok(); }
  // A frame whose output pose is final (pipeline/odometry/odometry_trajectory.h), oldest first:
  // exactly one per input frame, lost and dropped ones included.
  virtual Status onFinishedFrame(const FinishedFrame& frame) = 0;
  // A keyframe that left the map, with its final pose and covariance.
  virtual Status onRetiredKeyframe(const RetiredKeyframe&) { return Status::Ok(); }
  // For viewers (viewer/, docs/VIEWER.md): after onFrame of a tracked (not dropped) frame and any
  // loop correction made for it, on the map stage's thread, a read-only look at what the frame
  // left (below). Nothing else changes those objects during the call, and they are valid only
  // during it. Must not block or allocate: copy what you need into preallocated storage.
  virtual void onFrameView(const FrameView&) {}
};

struct OdometryRunOptions {
  // The schedule (mode, slots, thread priority, pinning, mlock, clock): runtime/run_options.h.
  // Defaults for odometry: deterministic; 8 slots in the threaded modes (the front stages keep
  // working through a long local BA, ~2 frame periods, instead of stalling on a full pool), while
  // lock-step needs only one. end_to_end_stage and background_stages are set by runOdometry().
  runtime::RunOptions schedule = defaultSchedule();
  long max_frames = -1;          // > 0: stop after this many input frames (dropped ones count); -1: all
  uint64_t warmup_frames = 30;   // heap allocations are counted from this frame on
  bool keep_trace = false;       // copy the per-stage trace into the result (`--profile`)
  // Set (e.g. by a SIGINT handler) to end the run after the frames already read: a clean end of
  // input, so everything computed so far reaches the sink. nullptr: never.
  const std::atomic<bool>* stop = nullptr;
  // Loop closing (docs/LOOP.md): a loop stage after the map stage (lock-step in deterministic
  // mode, its own thread otherwise). On by default: on synth:loop it halves the optimised ATE and
  // on head250 and synth:repeated it accepts no loop (docs/LOOP.md "Measurements").
  bool loop_closing = true;
  loop::LoopCloserOptions loop;
  // How tracking follows the map stage (docs/RUNTIME.md "When the map stage falls behind"). 0: at
  // the fixed lag SystemOptions::map_lag_frames, lock-step's map, the deterministic bytes. > 0: the
  // newest snapshot, tracking at most this many frames past a keyframe it asked for before it
  // waits for the map stage to publish it (bounded staleness). -1 (default): by mode, 0 in
  // deterministic and fast, kRealtimeFramesAhead in realtime (the tracker does not wait for a
  // local BA; a lagging mapper backs up into the slot pool and frames drop, counted).
  int max_frames_ahead_of_mapper = -1;
  static constexpr int kRealtimeFramesAhead = 4;
  // Map files (docs/LOOP.md "Map files"). load_map: the run starts relocalizing into this map (its
  // camera must equal the system's; it needs at least one keyframe); its keyframes join the loop
  // closer's graph when loop closing is on. save_map: filled at the end of the run (whatever ended
  // it) with the loop closer's final graph and records and the system's camera; needs loop closing.
  const loop::SavedMap* load_map = nullptr;
  loop::SavedMap* save_map = nullptr;

  static runtime::RunOptions defaultSchedule() {
    runtime::RunOptions o;
    o.mode = runtime::RunMode::kDeterministic;
    o.slot_count = 8;
    return o;
  }
};

// Empty Status when usable; otherwise what is wrong (checked by RunSession::create before any work).
Status validate(const OdometryRunOptions& options);

// What loop closing did in a run (loop_closing on).
struct LoopRunResult {
  bool enabled = false;
  loop::LoopStats stats;
  uint64_t records_dropped = 0;        // threaded modes: the ring to the loop stage was full
  uint64_t corrections_published = 0;  // accepted loops sent to the mapping side
  std::size_t capacity = 0;            // keyframes the graph may hold
  std::size_t memory_bytes = 0;        // LoopCloser::memoryBytes()
  // Every keyframe of the final graph (id ascending) with its optimised pose: the optimised
  // trajectory re-expresses each frame through its reference keyframe's pose here.
  std::vector<std::pair<uint32_t, Eigen::Isometry3d>> keyframes;
  // The loop audit (pipeline/loop/loop_audit.h), copied at the end of the run.
  std::vector<loop::LoopAuditEntry> audit;
  std::vector<loop::LoopAuditKeyframe> audit_keyframes;
  uint64_t audit_entries_dropped = 0;
  uint64_t audit_keyframes_dropped = 0;
  // The pose of `id` in the final graph; false when it is not there (culled, or never received).
  bool keyframePose(uint32_t id, Eigen::Isometry3d* T_world_cam) const;
  // Parallel to keyframes: each one's final local-map pose and the loop epoch of that pose
  // (LoopCloser::finalPose; has_final false when it never left the local map).
  struct FinalPose {
    bool has_final = false;
    uint64_t epoch = 0;
    Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  };
  std::vector<FinalPose> keyframe_finals;
  // The rigid motion of each loop correction the mapping side applied (OdometrySystem::
  // appliedCorrections): entry e - 1 takes the world of loop epoch e - 1 to that of epoch e.
  std::vector<Eigen::Isometry3d> epoch_corrections;
  // The graph pose of `id` and its final local-map pose expressed in the world of loop epoch
  // `epoch` (the corrections applied between `epoch` and the epoch the final pose was reported in
  // undone: they moved the whole local map rigidly, that keyframe included); false when it has no
  // final pose, or one reported before `epoch`, or those corrections were not recorded.
  bool keyframeFinalPose(uint32_t id, uint64_t epoch, Eigen::Isometry3d* T_world_graph,
                         Eigen::Isometry3d* T_world_final) const;
  // A finished frame's pose in the optimised trajectory (docs/LOOP.md "Two trajectories"): its
  // real-time pose moved as the graph moved its reference keyframe from the final local-map pose
  // (in the frame's loop epoch), else its reference keyframe's graph pose times T_ref_cam; false (pose
  // unchanged) when the frame has no pose or its reference keyframe is not in the graph.
  bool optimisedPose(const FinishedFrame& frame, Eigen::Isometry3d* T_world_cam) const;
};

struct OdometryRunResult {
  LoopRunResult loop;
  runtime::RunReport report;
  std::vector<runtime::TraceTrack> trace;  // keep_trace
  uint64_t frames = 0;          // frames tracked (not dropped)
  uint64_t frames_dropped = 0;  // real-time mode: no free slot (each has its `# <t> dropped` line)
  uint64_t extraction_failures = 0;  // frames whose image did not fit the camera (tracked featureless)
  uint64_t drops_without_trajectory_line = 0;  // dropped beyond the drop log's capacity (34 s stall)
  bool stopped = false;         // ended by options.stop
  // Heap allocations (process-wide operator new calls) over the frames the map stage finished from
  // warmup_frames on, until the capture found the input ended (thread exit allocates inside
  // OpenCV's thread-local cleanup: shutdown, not per-frame cost). The first such frame is the
  // baseline, so `allocation_frames` = frames counted after it.
  uint64_t allocation_frames = 0;
  uint64_t allocations_after_warmup = 0;
  double map_restore_ms = 0;  // load_map: loop closer + relocalizer filled (before the first frame)
  // The system's counters at the end of the run.
  OdometryStats odometry;
  MapperStats mapper;
  uint64_t mapper_waits = 0;  // threaded runs: times tracking waited for the map stage
};

// Builds the system for capture.camera() (options checked there and by validate()), runs every
// frame of `capture` through it in options.schedule's mode into `sink`, and finishes the run
// (RunSession). *result is filled also when the run failed part-way (what was computed).
Status runOdometry(FrameCapture& capture, const SystemOptions& system_options, OdometrySink& sink,
                   const OdometryRunOptions& options, OdometryRunResult* result);

}  // namespace plumb

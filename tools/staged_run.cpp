#include "tools/staged_run.h"

#include <atomic>
#include <cmath>
#include <cstdio>
#include <memory>
#include <utility>

#include "drivers/dataset/tum_dataset.h"
#include "pipeline/frontend/feature_extractor.h"
#include "platform/allocation_counter.h"
#include "runtime/chrome_trace.h"
#include "runtime/clock.h"
#include "runtime/doorbell.h"
#include "runtime/spsc_ring.h"
#include "runtime/stage_runner.h"

namespace plumb::tools {

namespace {

// Set by the capture stage when its source has no more frames. From then on the stage threads
// wind down, and a thread's exit allocates inside OpenCV's thread-local-storage cleanup: teardown,
// not per-frame cost, so the steady-state allocation window closes here (see MapStage).
using InputEnded = std::atomic<bool>;

// Frames the capture stage skipped (real-time: no free slot, or the source fell behind), on their
// way to the map stage, which writes them into the output trajectory in order: each slot says how
// many were skipped just before it; the rest are those after the last frame. Capacity: a stall of
// ~34 s at 30 Hz; beyond it a dropped frame gets no trajectory line (counted).
struct DroppedFrame {
  uint64_t sequence = 0;
  double timestamp_s = 0;
};
struct DropLog {
  static constexpr std::size_t kCapacity = 1024;
  runtime::SpscRing<DroppedFrame> ring{kCapacity};
  uint64_t not_logged = 0;  // capture thread only

  // Capture side; true when the drop will reach the map stage.
  bool log(uint64_t sequence, double timestamp_s) {
    if (ring.try_push(DroppedFrame{sequence, timestamp_s})) return true;
    ++not_logged;
    return false;
  }
};

// What one slot carries through the stages. FrameFeatures is large (fixed capacities), so it lives
// on the heap, allocated once with the slot.
struct OdometrySlot {
  RgbdImage image;
  std::unique_ptr<FrameFeatures> features = std::make_unique<FrameFeatures>();
  std::unique_ptr<TrackedFrame> tracked = std::make_unique<TrackedFrame>();  // track -> map
  uint32_t dropped_before = 0;  // DropLog entries that precede this frame
};

// Stage 0. FrameSource has no "peek", so the next frame is read ahead into a staging image; read()
// swaps it into the slot (cv::Mat headers only: the staging image takes over the slot's previous
// buffers, which the source refills in place next time), skip() just forgets it. In real-time
// replay the decode therefore happens before the frame's due time, like a camera delivering a
// finished frame.
class CaptureStage final : public runtime::Source<OdometrySlot> {
 public:
  CaptureStage(FrameSource& source, long max_frames, InputEnded& input_ended, DropLog& drops)
      : source_(source), max_frames_(max_frames), input_ended_(input_ended), drops_(drops) {}

  bool peekNext(int64_t* t_recorded_ns) override {
    if (staged_) {
      *t_recorded_ns = staged_t_ns_;
      return true;
    }
    if (max_frames_ >= 0 && consumed_ >= max_frames_) return ended();
    for (;;) {
      const SourceResult r = source_.next(staging_);
      if (r == SourceResult::kEndOfStream) return ended();
      if (r == SourceResult::kNoFrame) continue;  // live source timeout: ask again
      staged_ = true;
      if (r == SourceResult::kError) {
        // Delivered through read(), so it travels down the pipeline like any stage error.
        error_ = source_.lastError().withContext(source_.describe());
        staged_t_ns_ = last_t_ns_;
      } else {
        staged_t_ns_ = std::llround(staging_.timestamp_s * 1e9);
        last_t_ns_ = staged_t_ns_;
      }
      *t_recorded_ns = staged_t_ns_;
      return true;
    }
  }

  Status read(OdometrySlot& slot, const runtime::FrameStamps& stamps) override {
    staged_ = false;
    ++consumed_;
    if (!error_.ok()) return error_;
    std::swap(slot.image, staging_);
    slot.image.t_sensor_ns = stamps.t_sensor_ns;
    slot.dropped_before = dropped_since_read_;
    dropped_since_read_ = 0;
    return Status::Ok();
  }

  void skip() override {
    staged_ = false;
    ++consumed_;
    if (error_.ok()) dropped_since_read_ += drops_.log(staging_.sequence, staging_.timestamp_s);
  }

 private:
  bool ended() {
    input_ended_.store(true);
    return false;
  }

  FrameSource& source_;
  long max_frames_;
  InputEnded& input_ended_;
  DropLog& drops_;
  uint32_t dropped_since_read_ = 0;
  long consumed_ = 0;
  RgbdImage staging_;
  bool staged_ = false;
  int64_t staged_t_ns_ = 0;
  int64_t last_t_ns_ = 0;
  Status error_;
};

// Stage 0 for a TUM-layout replay: frames by index, timestamps from the frame list. The next frame
// is decoded AHEAD, in peekNext(), i.e. before the runner paces to its due time, and read() only
// swaps the finished image into the slot (cv::Mat headers; the buffers circulate). Decoding PNG
// files is an artefact of the storage format: a live sensor delivers a decoded frame at its
// timestamp, and so does this replay. The frame's sensor time stays its recorded due time, so
// end-to-end latency is not flattered; the decode shows in no stage's span (it runs while the
// capture thread would otherwise sleep until the due time). A frame the runner then skips (no
// free slot, source late) was decoded for nothing.
class TumReplayCapture final : public runtime::Source<OdometrySlot> {
 public:
  TumReplayCapture(TumDatasetSource& replay, long max_frames, InputEnded& input_ended, DropLog& drops)
      : replay_(replay), max_frames_(max_frames), input_ended_(input_ended), drops_(drops) {}

  bool peekNext(int64_t* t_recorded_ns) override {
    const bool at_end =
        next_ >= replay_.size() || (max_frames_ >= 0 && next_ >= static_cast<std::size_t>(max_frames_));
    if (at_end) {
      input_ended_.store(true);
      return false;
    }
    if (!staged_) {
      staged_status_ = replay_.load(next_, staging_);  // an error travels down through read()
      staged_ = true;
    }
    *t_recorded_ns = std::llround(replay_.timestamp(next_) * 1e9);
    return true;
  }
  Status read(OdometrySlot& slot, const runtime::FrameStamps& stamps) override {
    staged_ = false;
    ++next_;
    slot.dropped_before = dropped_since_read_;
    dropped_since_read_ = 0;
    if (!staged_status_.ok()) return staged_status_;
    std::swap(slot.image, staging_);
    slot.image.t_sensor_ns = stamps.t_sensor_ns;
    return Status::Ok();
  }
  void skip() override {
    staged_ = false;
    dropped_since_read_ += drops_.log(next_, replay_.timestamp(next_));
    ++next_;
  }

 private:
  TumDatasetSource& replay_;
  long max_frames_;
  InputEnded& input_ended_;
  DropLog& drops_;
  uint32_t dropped_since_read_ = 0;
  std::size_t next_ = 0;  // the replay's own cursor is not used: load() is random access
  RgbdImage staging_;
  bool staged_ = false;
  Status staged_status_;
};

// Stage 1: its own FeatureExtractor (extractors are one per thread), same options as the system's.
class ExtractStage final : public runtime::Stage<OdometrySlot> {
 public:
  explicit ExtractStage(const FeatureExtractor& like)
      : extractor_(like.camera(), like.options()) {}
  const char* name() const override { return "extract"; }
  Status process(OdometrySlot& slot, const runtime::FrameStamps&) override {
    // As OdometrySystem::processImage: a frame that does not fit the camera is tracked featureless.
    if (!extractor_.extract(slot.image, *slot.features)) {
      slot.features->clear();
      ++failures_;
    }
    return Status::Ok();
  }
  uint64_t failures() const { return failures_; }

 private:
  FeatureExtractor extractor_;
  uint64_t failures_ = 0;
};

// How far the map stage has got, for the track stage's MapperFence. Written by the map stage's
// thread after each frame (release), read by the track stage's (acquire).
struct MapperProgress {
  std::atomic<uint64_t> frames_mapped{0};
  std::atomic<bool> failed{false};  // the map stage stopped: nobody to wait for
  runtime::Doorbell bell;           // rung after every change above
};

// Stage 2: tracking and the keyframe decision. The keyframe request travels in the slot.
class TrackStage final : public runtime::Stage<OdometrySlot>, public MapperFence {
 public:
  // threaded: false for lock-step and for the single-threaded simulation of realtime mode on a
  // VirtualClock, where nobody else could move the map stage on (the simulation runs each step to
  // completion in virtual-time order, so the map stage may "later" map an earlier frame).
  TrackStage(OdometrySystem& system, MapperProgress& progress, bool threaded)
      : system_(system), progress_(progress), threaded_(threaded) {}
  const char* name() const override { return "track"; }
  Status process(OdometrySlot& slot, const runtime::FrameStamps&) override {
    system_.trackFeatures(*slot.features, slot.image.sequence, slot.image.timestamp_s, this, slot.tracked.get());
    ++frames_tracked_;
    return Status::Ok();
  }
  // Called (rarely: map start, relocalization) while frame frames_tracked_ is being tracked: the
  // map stage has done every earlier frame once frames_mapped reaches frames_tracked_. In lock-step
  // runs that is always already true.
  void waitForMapper() override {
    if (!threaded_) return;
    progress_.bell.waitUntil([this] {
      return progress_.failed.load(std::memory_order_acquire) ||
             progress_.frames_mapped.load(std::memory_order_acquire) >= frames_tracked_;
    });
  }

 private:
  OdometrySystem& system_;
  MapperProgress& progress_;
  bool threaded_;
  uint64_t frames_tracked_ = 0;
};

// Stage 3: local mapping for keyframe requests, output trajectory, the caller's bookkeeping.
class MapStage final : public runtime::Stage<OdometrySlot> {
 public:
  MapStage(OdometrySystem& system, MapperProgress& progress, DropLog& drops, const FrameOutputFn& on_output,
           uint64_t warmup_frames, const InputEnded& input_ended)
      : system_(system),
        progress_(progress),
        drops_(drops),
        on_output_(on_output),
        warmup_frames_(warmup_frames),
        input_ended_(input_ended) {}
  const char* name() const override { return "map"; }
  Status process(OdometrySlot& slot, const runtime::FrameStamps& stamps) override {
    Status status = writeDrops(slot.dropped_before);
    const FrameOutput& out = system_.mapFrame(*slot.tracked);
    if (status.ok() && on_output_) status = on_output_(out);
    // Process-wide count, read on this thread after each frame: from the first frame at or after
    // warm-up to the last one finished before the input ended, every thread's allocations are
    // included. The count is read before the flag, so a reading taken after a stage thread began
    // to exit is never kept.
    if (stamps.frame_index >= warmup_frames_) {
      const uint64_t now = allocationCount();
      if (!input_ended_.load()) {
        if (frames_after_warmup_ == 0) allocations_at_warmup_ = now;
        allocations_at_last_ = now;
        ++frames_after_warmup_;
      }
    }
    // Last: the mapper, relocalizer and system outputs are released to a waiting track stage.
    if (!status.ok()) progress_.failed.store(true, std::memory_order_release);
    progress_.frames_mapped.fetch_add(1, std::memory_order_release);
    progress_.bell.ring();
    return status;
  }
  // Frames dropped after the last processed one (the capture thread has finished: it sent the end
  // of stream this call follows).
  void finish() override {
    const Status status = writeDrops(UINT32_MAX);
    if (finish_status_.ok()) finish_status_ = status;
  }
  const Status& finishStatus() const { return finish_status_; }
  uint64_t framesAfterWarmup() const { return frames_after_warmup_; }
  uint64_t allocationsAfterWarmup() const { return allocations_at_last_ - allocations_at_warmup_; }

 private:
  // Up to `count` logged drops into the output trajectory, in order, through the caller's callback
  // (which drains the trajectory, so its delay FIFO never holds more than one burst).
  Status writeDrops(uint32_t count) {
    Status status;
    DroppedFrame dropped;
    for (uint32_t i = 0; i < count && drops_.ring.try_pop(dropped); ++i) {
      const FrameOutput& out = system_.mapDroppedFrame(dropped.sequence, dropped.timestamp_s);
      if (status.ok() && on_output_) status = on_output_(out);
    }
    return status;
  }

  OdometrySystem& system_;
  MapperProgress& progress_;
  DropLog& drops_;
  Status finish_status_;
  const FrameOutputFn& on_output_;
  uint64_t warmup_frames_;
  const InputEnded& input_ended_;
  uint64_t frames_after_warmup_ = 0;
  uint64_t allocations_at_warmup_ = 0;
  uint64_t allocations_at_last_ = 0;
};

}  // namespace

Status runStaged(FrameSource& source, OdometrySystem& system, const StagedRunOptions& options,
                 const FrameOutputFn& on_output, StagedRunResult* result) {
  // A TUM replay is read by index (timestamps from its list); any other source through next().
  InputEnded input_ended{false};
  DropLog drops;
  CaptureStage generic_capture(source, options.max_frames, input_ended, drops);
  auto* replay = dynamic_cast<TumDatasetSource*>(&source);
  std::unique_ptr<TumReplayCapture> replay_capture;
  if (replay != nullptr) {
    replay_capture = std::make_unique<TumReplayCapture>(*replay, options.max_frames, input_ended, drops);
  }
  runtime::Source<OdometrySlot>& capture =
      replay_capture ? static_cast<runtime::Source<OdometrySlot>&>(*replay_capture) : generic_capture;
  ExtractStage extract(system.extractor());
  MapperProgress progress;
  const bool simulated = options.mode == runtime::RunMode::kRealtime && options.clock != nullptr &&
                         options.clock->isVirtual();
  TrackStage track(system, progress, options.mode != runtime::RunMode::kDeterministic && !simulated);
  MapStage map(system, progress, drops, on_output, options.warmup_frames, input_ended);
  runtime::RunOptions run_options;
  run_options.mode = options.mode;
  run_options.slot_count = options.slot_count;
  run_options.realtime_priority = options.realtime_priority;
  run_options.pin_threads = options.pin_threads;
  run_options.lock_memory = options.lock_memory;
  run_options.clock = options.clock;
  // Real time: mapping is off the latency path (poses are known when tracking is done), so under
  // contention the kernel serves capture, extract and track first. Nice 5, not more: the map stage
  // must still keep up on average, or the slots fill and frames drop. Not in fast mode, where
  // every stage is on the throughput path.
  if (options.mode == runtime::RunMode::kRealtime) {
    run_options.background_stages = 1u << 3;
    run_options.background_nice = 5;
  }
  // End to end = sensor time to pose known (track done); the map stage refines later frames' map.
  run_options.end_to_end_stage = 2;
  runtime::StageRunner<OdometrySlot> runner(capture, {&extract, &track, &map}, run_options);
  Status status = runner.run();
  if (status.ok()) status = map.finishStatus();

  result->report = runner.report();
  result->extraction_failures = extract.failures();
  result->drops_without_trajectory_line = drops.not_logged;
  result->frames_after_warmup = map.framesAfterWarmup();
  result->allocations_after_warmup = map.allocationsAfterWarmup();
  if (!options.profile_path.empty()) {
    PLUMB_RETURN_IF_ERROR(runtime::writeChromeTrace(options.profile_path, runner.trace(), runner.report()));
    if (options.print_profile) {
      std::printf("%s", runtime::formatRunReport(runner.report()).c_str());
      std::printf("trace: %s (open in ui.perfetto.dev; `plumb profile %s --png hist.png`)\n",
                  options.profile_path.c_str(), options.profile_path.c_str());
    }
  }
  return status;
}

const std::set<std::string>& stagedRunValueOptions() {
  static const std::set<std::string> options = {"mode", "profile", "slots", "rt-priority"};
  return options;
}

const std::set<std::string>& stagedRunFlagOptions() {
  static const std::set<std::string> options = {"pin-threads", "mlock"};
  return options;
}

const char* stagedRunUsage() {
  return "  --mode M             deterministic (stages in lock-step on one thread), fast (a thread\n"
         "                       per stage, no drops) or realtime (threads, paced to the recorded\n"
         "                       timestamps, a frame finding no free slot is dropped and counted)\n"
         "  --profile FILE       write a Chrome trace (Perfetto / chrome://tracing) and print\n"
         "                       p50/p90/p99/max per stage and end to end, drops, frames/s\n"
         "  --slots N            frame slots in flight (default 8)\n"
         "  --rt-priority P      SCHED_FIFO priority 1..99 for stage threads (falls back if refused)\n"
         "  --pin-threads        pin stage threads to CPUs\n"
         "  --mlock              lock process memory (falls back if refused)\n";
}

Status parseStagedRunOptions(const Args& args, StagedRunOptions* options) {
  if (args.has("mode")) PLUMB_RETURN_IF_ERROR(runtime::parseRunMode(args.get("mode"), &options->mode));
  options->profile_path = args.get("profile");
  bool ok = true;
  const long slots = args.getInt("slots", static_cast<long>(options->slot_count), &ok);
  const long priority = args.getInt("rt-priority", options->realtime_priority, &ok);
  if (!ok) return Status::Error("--slots and --rt-priority take integers");
  if (slots < 1 || slots > 64) return Status::Error("--slots must be within 1..64");
  if (priority < 0 || priority > 99) return Status::Error("--rt-priority must be within 0..99");
  options->slot_count = static_cast<std::size_t>(slots);
  options->realtime_priority = static_cast<int>(priority);
  options->pin_threads = args.has("pin-threads");
  options->lock_memory = args.has("mlock");
  return Status::Ok();
}

}  // namespace plumb::tools

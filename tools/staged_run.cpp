#include "tools/staged_run.h"

#include <atomic>
#include <cmath>
#include <cstdio>
#include <memory>
#include <utility>

#include "drivers/dataset/tum_dataset.h"
#include "pipeline/feature_extractor.h"
#include "platform/allocation_counter.h"
#include "runtime/chrome_trace.h"
#include "runtime/stage_runner.h"

namespace plumb::tools {

namespace {

// Set by the capture stage when its source has no more frames. From then on the stage threads
// wind down, and a thread's exit allocates inside OpenCV's thread-local-storage cleanup: teardown,
// not per-frame cost, so the steady-state allocation window closes here (see OdometryStage).
using InputEnded = std::atomic<bool>;

// What one slot carries through the stages. FrameFeatures is large (fixed capacities), so it lives
// on the heap, allocated once with the slot.
struct OdometrySlot {
  RgbdImage image;
  std::unique_ptr<FrameFeatures> features = std::make_unique<FrameFeatures>();
};

// Stage 0. FrameSource has no "peek", so the next frame is read ahead into a staging image; read()
// swaps it into the slot (cv::Mat headers only: the staging image takes over the slot's previous
// buffers, which the source refills in place next time), skip() just forgets it. In real-time
// replay the decode therefore happens before the frame's due time, like a camera delivering a
// finished frame.
class CaptureStage final : public runtime::Source<OdometrySlot> {
 public:
  CaptureStage(FrameSource& source, long max_frames, InputEnded& input_ended)
      : source_(source), max_frames_(max_frames), input_ended_(input_ended) {}

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
    return Status::Ok();
  }

  void skip() override {
    staged_ = false;
    ++consumed_;
  }

 private:
  bool ended() {
    input_ended_.store(true);
    return false;
  }

  FrameSource& source_;
  long max_frames_;
  InputEnded& input_ended_;
  long consumed_ = 0;
  RgbdImage staging_;
  bool staged_ = false;
  int64_t staged_t_ns_ = 0;
  int64_t last_t_ns_ = 0;
  Status error_;
};

// Stage 0 for a TUM-layout replay: timestamps come from the frame list, so peeking and skipping
// cost nothing and only frames that get a slot are decoded (straight into the slot). In real-time
// mode a replay that decodes every frame ahead falls behind as soon as decoding is slower than the
// frame rate; this one only decodes what it delivers.
class TumReplayCapture final : public runtime::Source<OdometrySlot> {
 public:
  TumReplayCapture(TumDatasetSource& replay, long max_frames, InputEnded& input_ended)
      : replay_(replay), max_frames_(max_frames), input_ended_(input_ended) {}

  bool peekNext(int64_t* t_recorded_ns) override {
    const bool at_end =
        next_ >= replay_.size() || (max_frames_ >= 0 && next_ >= static_cast<std::size_t>(max_frames_));
    if (at_end) {
      input_ended_.store(true);
      return false;
    }
    *t_recorded_ns = std::llround(replay_.timestamp(next_) * 1e9);
    return true;
  }
  Status read(OdometrySlot& slot, const runtime::FrameStamps& stamps) override {
    const Status status = replay_.load(next_++, slot.image);
    slot.image.t_sensor_ns = stamps.t_sensor_ns;
    return status;
  }
  void skip() override { ++next_; }

 private:
  TumDatasetSource& replay_;
  long max_frames_;
  InputEnded& input_ended_;
  std::size_t next_ = 0;  // the replay's own cursor is not used: load() is random access
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

// Stage 2: tracking, keyframe decision and local mapping, in frame order.
class OdometryStage final : public runtime::Stage<OdometrySlot> {
 public:
  OdometryStage(OdometrySystem& system, const FrameOutputFn& on_output, uint64_t warmup_frames,
                const InputEnded& input_ended)
      : system_(system), on_output_(on_output), warmup_frames_(warmup_frames), input_ended_(input_ended) {}
  const char* name() const override { return "odometry"; }
  Status process(OdometrySlot& slot, const runtime::FrameStamps& stamps) override {
    const FrameOutput& out =
        system_.processFeatures(*slot.features, slot.image.sequence, slot.image.timestamp_s);
    Status status = on_output_ ? on_output_(out) : Status::Ok();
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
    return status;
  }
  uint64_t framesAfterWarmup() const { return frames_after_warmup_; }
  uint64_t allocationsAfterWarmup() const { return allocations_at_last_ - allocations_at_warmup_; }

 private:
  OdometrySystem& system_;
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
  // A TUM replay is read by index (cheap peek/skip); any other source through next() + read-ahead.
  InputEnded input_ended{false};
  CaptureStage generic_capture(source, options.max_frames, input_ended);
  auto* replay = dynamic_cast<TumDatasetSource*>(&source);
  std::unique_ptr<TumReplayCapture> replay_capture;
  if (replay != nullptr) {
    replay_capture = std::make_unique<TumReplayCapture>(*replay, options.max_frames, input_ended);
  }
  runtime::Source<OdometrySlot>& capture =
      replay_capture ? static_cast<runtime::Source<OdometrySlot>&>(*replay_capture) : generic_capture;
  ExtractStage extract(system.extractor());
  OdometryStage odometry(system, on_output, options.warmup_frames, input_ended);
  runtime::RunOptions run_options;
  run_options.mode = options.mode;
  run_options.slot_count = options.slot_count;
  run_options.realtime_priority = options.realtime_priority;
  run_options.pin_threads = options.pin_threads;
  run_options.lock_memory = options.lock_memory;
  runtime::StageRunner<OdometrySlot> runner(capture, {&extract, &odometry}, run_options);
  const Status status = runner.run();

  result->report = runner.report();
  result->extraction_failures = extract.failures();
  result->frames_after_warmup = odometry.framesAfterWarmup();
  result->allocations_after_warmup = odometry.allocationsAfterWarmup();
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
         "  --slots N            frame slots in flight (default 4)\n"
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

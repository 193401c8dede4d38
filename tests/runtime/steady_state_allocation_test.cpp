// The steady-state contract: once warmed up, a frame through the threaded pipeline allocates
// nothing (no new/delete anywhere in the process while frames 30..199 flow).
#include <gtest/gtest.h>

#include <atomic>

#include "platform/allocation_counter.h"
#include "runtime/stage_runner.h"
#include "toy_pipeline.h"

namespace plumb::runtime {
namespace {

using testing::FoldStage;
using testing::MixStage;
using testing::ToyFrame;
using testing::ToySource;

constexpr uint64_t kSteadyFrames = 200;
constexpr uint64_t kWarmupFrames = 30;

// Reads the process-wide allocation counter when the first frame at or after kWarmupFrames enters
// the pipeline, and after every frame at the end of it: the last reading is after the last frame.
// (Real-time mode may drop a frame on a loaded machine; the contract holds for those too.)
class CountingSource final : public Source<ToyFrame> {
 public:
  explicit CountingSource(std::atomic<uint64_t>* at_warm) : inner_(kSteadyFrames, 2'000'000), at_warm_(at_warm) {}
  bool peekNext(int64_t* t) override { return inner_.peekNext(t); }
  Status read(ToyFrame& frame, const FrameStamps& stamps) override {
    if (!warm_ && stamps.frame_index >= kWarmupFrames) {
      at_warm_->store(allocationCount());
      warm_ = true;
    }
    return inner_.read(frame, stamps);
  }
  void skip() override { inner_.skip(); }

 private:
  ToySource inner_;
  std::atomic<uint64_t>* at_warm_;
  bool warm_ = false;
};

class CountingSink final : public Stage<ToyFrame> {
 public:
  explicit CountingSink(std::atomic<uint64_t>* at_end) : at_end_(at_end) {}
  const char* name() const override { return "sink"; }
  Status process(ToyFrame&, const FrameStamps& stamps) override {
    if (stamps.frame_index >= kWarmupFrames) {
      at_end_->store(allocationCount());
      ++steady_frames_;
    }
    return Status::Ok();
  }

 private:
  std::atomic<uint64_t>* at_end_;
  uint64_t steady_frames_ = 0;

 public:
  uint64_t steadyFrames() const { return steady_frames_; }
};

class SteadyState : public ::testing::TestWithParam<RunMode> {};

TEST_P(SteadyState, ZeroAllocationsPerFrameAfterWarmup) {
  std::atomic<uint64_t> at_warm{0};
  std::atomic<uint64_t> at_end{0};
  CountingSource source(&at_warm);
  MixStage mix;
  FoldStage fold(kSteadyFrames);
  CountingSink sink(&at_end);
  RunOptions options;
  options.mode = GetParam();
  options.slot_count = 3;
  // Real-time replay at 500 Hz: fast enough to keep the test short (0.4 s). On a loaded machine a
  // stage thread may sleep for tens of ms: 32 slots (64 ms of frames) and no late-frame skipping
  // keep enough frames to judge (with 3 slots and the 50 ms skip a loaded run kept 30 of 170).
  if (GetParam() == RunMode::kRealtime) {
    options.slot_count = 32;
    options.max_source_lag_ns = 0;
  }
  StageRunner<ToyFrame> runner(source, {&mix, &fold, &sink}, options);
  ASSERT_TRUE(runner.run().ok());
  if (GetParam() != RunMode::kRealtime) {
    ASSERT_EQ(runner.report().frames_completed, kSteadyFrames);
  }
  ASSERT_GE(sink.steadyFrames(), (kSteadyFrames - kWarmupFrames) / 2) << "too few frames to judge";
  ASSERT_GT(at_warm.load(), 0u);
  ASSERT_GE(at_end.load(), at_warm.load());
  const uint64_t allocations = at_end.load() - at_warm.load();
  EXPECT_EQ(allocations, 0u) << allocations << " allocations over " << kSteadyFrames - kWarmupFrames
                             << " steady-state frames";
}

INSTANTIATE_TEST_SUITE_P(Modes, SteadyState,
                         ::testing::Values(RunMode::kFast, RunMode::kRealtime, RunMode::kDeterministic),
                         [](const auto& info) { return std::string(runModeName(info.param)); });

}  // namespace
}  // namespace plumb::runtime

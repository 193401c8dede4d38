#include "runtime/stage_runner.h"
#include "runtime/function_stage.h"

#include <gtest/gtest.h>

#include "toy_pipeline.h"

namespace plumb::runtime {
namespace {

using testing::FoldStage;
using testing::MixStage;
using testing::ToyFrame;
using testing::ToySource;

constexpr uint64_t kFrames = 500;
constexpr int64_t kPeriodNs = 1'000'000;

struct RunResult {
  Status status;
  RunReport report;
  std::vector<uint64_t> outputs;
  std::vector<uint64_t> frame_indices;
  bool finished = false;
  std::size_t free_slots_after = 0;
  std::size_t slot_count = 0;
};

RunResult runToy(RunMode mode, int64_t source_fail_at = -1, int64_t fold_fail_at = -1,
                 std::size_t slots = 4) {
  ToySource source(kFrames, kPeriodNs, source_fail_at);
  MixStage mix;
  FoldStage fold(kFrames, fold_fail_at);
  RunOptions options;
  options.mode = mode;
  options.slot_count = slots;
  StageRunner<ToyFrame> runner(source, {&mix, &fold}, options);
  RunResult result;
  result.status = runner.run();
  result.report = runner.report();
  result.outputs = fold.outputs();
  result.frame_indices = fold.frameIndices();
  result.finished = fold.finished();
  result.free_slots_after = runner.pool().freeCount();
  result.slot_count = runner.pool().size();
  return result;
}

class EveryMode : public ::testing::TestWithParam<RunMode> {};

TEST_P(EveryMode, EndOfStreamReachesEveryStageAfterAllFrames) {
  const RunResult r = runToy(GetParam());
  ASSERT_TRUE(r.status.ok()) << r.status.message();
  EXPECT_TRUE(r.finished);
  EXPECT_EQ(r.outputs.size(), kFrames);
  EXPECT_EQ(r.report.frames_read, kFrames);
  EXPECT_EQ(r.report.frames_completed, kFrames);
  EXPECT_EQ(r.report.frames_dropped, 0u);
  EXPECT_EQ(r.report.end_to_end.count(), kFrames);
  ASSERT_EQ(r.report.stages.size(), 3u);
  EXPECT_EQ(r.report.stages[0].name, "capture");
  EXPECT_EQ(r.report.stages[2].name, "fold");
  EXPECT_EQ(r.report.stages[1].latency.count(), kFrames);
  for (uint64_t i = 0; i < r.frame_indices.size(); ++i) ASSERT_EQ(r.frame_indices[i], i);
  EXPECT_EQ(r.free_slots_after, r.slot_count) << "a slot never came back";
}

TEST_P(EveryMode, AStageErrorStopsThePipelineAndReturnsEverySlot) {
  const RunResult r = runToy(GetParam(), -1, /*fold_fail_at=*/100);
  ASSERT_FALSE(r.status.ok());
  EXPECT_NE(r.status.message().find("stage fold"), std::string::npos) << r.status.message();
  EXPECT_NE(r.status.message().find("refuses frame 100"), std::string::npos);
  EXPECT_EQ(r.outputs.size(), 100u);  // frames 0..99, nothing after the failure
  EXPECT_FALSE(r.finished);           // finish() means "all frames processed": not after an error
  EXPECT_LT(r.report.frames_read, kFrames);  // the source stopped early
  EXPECT_EQ(r.free_slots_after, r.slot_count);
}

TEST_P(EveryMode, ASourceErrorTravelsDownstream) {
  const RunResult r = runToy(GetParam(), /*source_fail_at=*/7);
  ASSERT_FALSE(r.status.ok());
  EXPECT_NE(r.status.message().find("stage capture"), std::string::npos) << r.status.message();
  EXPECT_NE(r.status.message().find("frame 7 unreadable"), std::string::npos);
  EXPECT_EQ(r.outputs.size(), 7u);
  EXPECT_EQ(r.free_slots_after, r.slot_count);
}

INSTANTIATE_TEST_SUITE_P(Modes, EveryMode,
                         ::testing::Values(RunMode::kDeterministic, RunMode::kFast),
                         [](const auto& info) { return std::string(runModeName(info.param)); });

TEST(StageRunner, LockStepAndThreadedRunsGiveIdenticalOutputs) {
  const RunResult lockstep = runToy(RunMode::kDeterministic);
  for (std::size_t slots : {1u, 2u, 7u}) {
    const RunResult threaded = runToy(RunMode::kFast, -1, -1, slots);
    ASSERT_TRUE(threaded.status.ok());
    EXPECT_EQ(threaded.outputs, lockstep.outputs) << slots << " slots";
  }
}

TEST(StageRunner, RealtimeOnTheRealClockPacesToTheRecording) {
  // 20 frames recorded 2 ms apart must take about 38 ms; cheap stages drop nothing.
  ToySource source(20, 2'000'000);
  MixStage mix;
  FoldStage fold(20);
  RunOptions options;
  options.mode = RunMode::kRealtime;
  StageRunner<ToyFrame> runner(source, {&mix, &fold}, options);
  const int64_t start = monotonicClock().nowNs();
  ASSERT_TRUE(runner.run().ok());
  const int64_t elapsed = monotonicClock().nowNs() - start;
  EXPECT_GE(elapsed, 38'000'000);
  EXPECT_EQ(runner.report().frames_completed + runner.report().frames_dropped, 20u);
}

TEST(StageRunner, TooManyStagesIsAClearError) {
  ToySource source(1, kPeriodNs);
  std::vector<MixStage> mixes(kMaxStages);
  std::vector<Stage<ToyFrame>*> stages;
  for (MixStage& m : mixes) stages.push_back(&m);
  StageRunner<ToyFrame> runner(source, stages, RunOptions{});
  const Status status = runner.run();
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("at most"), std::string::npos);
}

TEST(FunctionStage, ACallableIsAStageInEveryMode) {
  for (RunMode mode : {RunMode::kDeterministic, RunMode::kFast}) {
    ToySource source(50, kPeriodNs);
    uint64_t sum = 0;  // written only by the stage's thread, read after run()
    auto double_it = makeFunctionStage<ToyFrame>("double", [](ToyFrame& f, const FrameStamps&) {
      f.value *= 2;
      return Status::Ok();
    });
    auto add_up = makeFunctionStage<ToyFrame>("sum", [&sum](ToyFrame& f, const FrameStamps&) {
      sum += f.value;
      return Status::Ok();
    });
    RunOptions options;
    options.mode = mode;
    StageRunner<ToyFrame> runner(source, {&double_it, &add_up}, options);
    ASSERT_TRUE(runner.run().ok());
    uint64_t expected = 0;
    for (uint64_t n = 0; n < 50; ++n) expected += 2 * (n * 0x9E3779B97F4A7C15ull + 1);
    EXPECT_EQ(sum, expected) << runModeName(mode);
    EXPECT_EQ(runner.report().stages[1].name, "double");
  }
}

}  // namespace
}  // namespace plumb::runtime

// Real-time mode on a VirtualClock: pacing and dropping are simulated event by event, so a stage
// made slow (it advances the virtual clock) drops exactly the frames worked out by hand below.
#include <gtest/gtest.h>

#include "runtime/stage_runner.h"
#include "toy_pipeline.h"

namespace plumb::runtime {
namespace {

using testing::FoldStage;
using testing::MixStage;
using testing::ToyFrame;
using testing::ToySource;

constexpr int64_t kSimulatedMs = 1'000'000;

struct Simulated {
  std::vector<uint64_t> processed;  // frame indices that reached the last stage
  std::vector<uint64_t> dropped;    // from the source's trace track
  RunReport report;
  int64_t end_time_ns = 0;
  std::size_t free_slots_after = 0;
};

Simulated simulate(uint64_t frames, int64_t period_ns, std::size_t slots, int64_t mix_cost_ns,
                   int64_t fold_cost_ns, int end_to_end_stage = 0) {
  VirtualClock clock;
  ToySource source(frames, period_ns);
  MixStage mix(&clock, mix_cost_ns);
  FoldStage fold(frames, -1, &clock, fold_cost_ns);
  RunOptions options;
  options.mode = RunMode::kRealtime;
  options.slot_count = slots;
  options.clock = &clock;
  options.end_to_end_stage = end_to_end_stage;
  StageRunner<ToyFrame> runner(source, {&mix, &fold}, options);
  Simulated result;
  const Status status = runner.run();
  EXPECT_TRUE(status.ok()) << status.message();
  result.processed = fold.frameIndices();
  for (const TraceRecord& r : runner.trace()[0].records()) {
    if (r.kind == TraceRecord::Kind::kDrop) result.dropped.push_back(r.frame_index);
  }
  result.report = runner.report();
  result.end_time_ns = clock.nowNs();
  result.free_slots_after = runner.pool().freeCount();
  EXPECT_EQ(source.consumed(), frames) << "dropped frames must still be consumed (skipped)";
  return result;
}

TEST(RealtimeSimulation, ASlowStageDropsExactlyTheFramesThatFindNoFreeSlot) {
  // Frames every 10 ms, 2 slots, "mix" takes 25 ms. By hand (times in ms):
  //   f0 @0  slot free        mix 0-25    released 25
  //   f1 @10 1 in flight      mix 25-50   released 50
  //   f2 @20 f0, f1 in flight -> drop
  //   f3 @30 f0 back at 25    mix 50-75   released 75
  //   f4 @40 f1, f3           -> drop
  //   f5 @50 f1 back at 50    mix 75-100  released 100   (a release at t serves a capture at t)
  //   f6 @60, f7 @70          -> drop, drop
  //   f8 @80 f3 back at 75    mix 100-125
  //   f9 @90 f5, f8           -> drop
  const Simulated r = simulate(10, 10 * kSimulatedMs, 2, 25 * kSimulatedMs, 0);
  EXPECT_EQ(r.processed, (std::vector<uint64_t>{0, 1, 3, 5, 8}));
  EXPECT_EQ(r.dropped, (std::vector<uint64_t>{2, 4, 6, 7, 9}));
  EXPECT_EQ(r.report.frames_dropped, 5u);
  EXPECT_EQ(r.report.frames_completed, 5u);
  // End to end (done - sensor time): 25, 40, 45, 50, 45 ms.
  EXPECT_EQ(r.report.end_to_end.count(), 5u);
  EXPECT_EQ(r.report.end_to_end.maxNs(), 50 * kSimulatedMs);
  EXPECT_EQ(r.report.end_to_end.minNs(), 25 * kSimulatedMs);
  EXPECT_DOUBLE_EQ(r.report.end_to_end.meanNs(), 41.0 * kSimulatedMs);
  EXPECT_EQ(r.report.stages[1].latency.maxNs(), 25 * kSimulatedMs);
  EXPECT_EQ(r.end_time_ns, 125 * kSimulatedMs);
  EXPECT_EQ(r.free_slots_after, 2u);
}

TEST(RealtimeSimulation, StagesOverlapLikeThreads) {
  // Two 8 ms stages at 10 ms per frame: a frame is in flight 16 ms, but mix works on frame n+1
  // while fold works on frame n, so two slots suffice and nothing drops.
  const Simulated r = simulate(30, 10 * kSimulatedMs, 2, 8 * kSimulatedMs, 8 * kSimulatedMs);
  EXPECT_TRUE(r.dropped.empty());
  EXPECT_EQ(r.report.frames_completed, 30u);
  EXPECT_EQ(r.report.end_to_end.minNs(), 16 * kSimulatedMs);
  EXPECT_EQ(r.report.end_to_end.maxNs(), 16 * kSimulatedMs);
  EXPECT_EQ(r.end_time_ns, 29 * 10 * kSimulatedMs + 16 * kSimulatedMs);
}

TEST(RealtimeSimulation, OneSlotMeansOneFrameInFlight) {
  // Same stages, one slot: each frame holds it for 16 ms, so every other frame finds it taken.
  const Simulated r = simulate(10, 10 * kSimulatedMs, 1, 8 * kSimulatedMs, 8 * kSimulatedMs);
  EXPECT_EQ(r.processed, (std::vector<uint64_t>{0, 2, 4, 6, 8}));
  EXPECT_EQ(r.dropped, (std::vector<uint64_t>{1, 3, 5, 7, 9}));
}

TEST(RealtimeSimulation, FastEnoughStagesDropNothingAndLatencyIsTheirCost) {
  const Simulated r = simulate(100, 33 * kSimulatedMs, 4, 5 * kSimulatedMs, 7 * kSimulatedMs);
  EXPECT_TRUE(r.dropped.empty());
  EXPECT_EQ(r.report.frames_completed, 100u);
  EXPECT_EQ(r.report.end_to_end.maxNs(), 12 * kSimulatedMs);
  EXPECT_EQ(r.report.end_to_end.percentileNs(0.99), 12 * kSimulatedMs);
}

TEST(RealtimeSimulation, EndToEndCanEndAtAnEarlierStage) {
  // As above, but end to end stops when "mix" is done (for plumb: the pose is known when tracking
  // is done; mapping after it refines the map): 5 ms, the fold stage's 7 ms not included.
  const Simulated r = simulate(100, 33 * kSimulatedMs, 4, 5 * kSimulatedMs, 7 * kSimulatedMs, 1);
  EXPECT_EQ(r.report.frames_completed, 100u);
  EXPECT_EQ(r.report.end_to_end.maxNs(), 5 * kSimulatedMs);
  EXPECT_EQ(r.report.end_to_end_stage, 1);
  EXPECT_NE(formatRunReport(r.report).find("sensor time to 'mix' done"), std::string::npos)
      << formatRunReport(r.report);
  EXPECT_EQ(simulate(5, 33 * kSimulatedMs, 4, 5 * kSimulatedMs, 7 * kSimulatedMs).report.end_to_end_stage, 2);  // default: last
}

TEST(RealtimeSimulation, ASourceThatFallsBehindSkipsLateFramesInsteadOfLaggingForever) {
  // Reading a frame takes 15 ms but frames are due every 10 ms; frames reached more than 12 ms
  // after their due time are skipped. By hand (capture start = max(due, source free)):
  //   f0 due 0  start 0  lag 0    f1 due 10 start 15 lag 5    f2 due 20 start 30 lag 10
  //   f3 due 30 start 45 lag 15 -> late (skipping costs nothing)
  //   f4 due 40 start 45 lag 5    f5 due 50 start 60 lag 10   f6 due 60 start 75 lag 15 -> late
  //   f7 due 70 start 75 lag 5    f8 due 80 start 90 lag 10   f9 due 90 start 105 lag 15 -> late
  VirtualClock clock;
  ToySource source(10, 10 * kSimulatedMs, -1, &clock, 15 * kSimulatedMs);
  MixStage mix;
  FoldStage fold(10);
  RunOptions options;
  options.mode = RunMode::kRealtime;
  options.clock = &clock;
  options.max_source_lag_ns = 12 * kSimulatedMs;
  StageRunner<ToyFrame> runner(source, {&mix, &fold}, options);
  ASSERT_TRUE(runner.run().ok());
  std::vector<uint64_t> late;
  for (const TraceRecord& r : runner.trace()[0].records()) {
    if (r.kind == TraceRecord::Kind::kLate) late.push_back(r.frame_index);
  }
  EXPECT_EQ(late, (std::vector<uint64_t>{3, 6, 9}));
  EXPECT_EQ(runner.report().frames_late, 3u);
  EXPECT_EQ(runner.report().frames_dropped, 0u);
  EXPECT_EQ(fold.frameIndices(), (std::vector<uint64_t>{0, 1, 2, 4, 5, 7, 8}));
  // End to end includes the source's lag: f2 was due at 20 and done at 45.
  EXPECT_EQ(runner.report().end_to_end.maxNs(), 25 * kSimulatedMs);
  EXPECT_EQ(source.consumed(), 10u);

  // Without the limit every frame is read, ever later: f9 is due at 90 and done at 150.
  VirtualClock clock2;
  ToySource source2(10, 10 * kSimulatedMs, -1, &clock2, 15 * kSimulatedMs);
  FoldStage fold2(10);
  options.clock = &clock2;
  options.max_source_lag_ns = 0;
  StageRunner<ToyFrame> unlimited(source2, {&mix, &fold2}, options);
  ASSERT_TRUE(unlimited.run().ok());
  EXPECT_EQ(unlimited.report().frames_late, 0u);
  EXPECT_EQ(unlimited.report().frames_completed, 10u);
  EXPECT_EQ(unlimited.report().end_to_end.maxNs(), 60 * kSimulatedMs);
}

TEST(RealtimeSimulation, IsReproducible) {
  const Simulated a = simulate(200, 10 * kSimulatedMs, 3, 13 * kSimulatedMs, 9 * kSimulatedMs);
  const Simulated b = simulate(200, 10 * kSimulatedMs, 3, 13 * kSimulatedMs, 9 * kSimulatedMs);
  EXPECT_EQ(a.processed, b.processed);
  EXPECT_EQ(a.dropped, b.dropped);
  EXPECT_FALSE(a.dropped.empty());  // 13 ms per frame cannot keep up with 10 ms
  EXPECT_EQ(a.processed.size() + a.dropped.size(), 200u);
}

}  // namespace
}  // namespace plumb::runtime

// plumb_bench_runtime: numbers for the runtime alone (no odometry):
//   1. SpscRing hand-off throughput between two threads;
//   2. a synthetic 3-stage pipeline (fixed CPU work per stage): frames per second single-threaded
//      (lock-step) vs threaded (fast mode), and real-time replay at 30 Hz: p99 end-to-end latency
//      and dropped frames.
// Usage: plumb_bench_runtime [--trace out.json]   (trace of the real-time run, for plumb profile)
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>

#include "platform/monotonic_time.h"
#include "runtime/chrome_trace.h"
#include "runtime/spsc_ring.h"
#include "runtime/stage_runner.h"

namespace plumb::runtime {
namespace {

double ringItemsPerSecond(uint64_t items) {
  SpscRing<uint64_t> ring(1024);
  const int64_t start = monotonicNowNs();
  std::thread consumer([&] {
    uint64_t v = 0;
    for (uint64_t n = 0; n < items;) {
      if (ring.try_pop(v)) ++n;
    }
  });
  for (uint64_t i = 0; i < items; ++i) {
    while (!ring.try_push(i)) {
    }
  }
  consumer.join();
  return static_cast<double>(items) * 1e9 / static_cast<double>(monotonicNowNs() - start);
}

struct WorkFrame {
  uint64_t value = 0;
};

class CountingSource final : public Source<WorkFrame> {
 public:
  CountingSource(uint64_t frames, int64_t period_ns) : frames_(frames), period_ns_(period_ns) {}
  bool peekNext(int64_t* t) override {
    if (next_ >= frames_) return false;
    *t = static_cast<int64_t>(next_) * period_ns_;
    return true;
  }
  Status read(WorkFrame& frame, const FrameStamps&) override {
    frame.value = next_++;
    return Status::Ok();
  }
  void skip() override { ++next_; }

 private:
  uint64_t frames_;
  int64_t period_ns_;
  uint64_t next_ = 0;
};

// Burns a fixed amount of CPU (iterations of a dependent multiply chain).
class WorkStage final : public Stage<WorkFrame> {
 public:
  WorkStage(const char* name, uint64_t iterations) : name_(name), iterations_(iterations) {}
  const char* name() const override { return name_; }
  Status process(WorkFrame& frame, const FrameStamps&) override {
    uint64_t x = frame.value | 1;
    for (uint64_t i = 0; i < iterations_; ++i) x = x * 6364136223846793005ull + 1442695040888963407ull;
    frame.value = x;
    return Status::Ok();
  }

 private:
  const char* name_;
  uint64_t iterations_;
};

RunReport runWork(RunMode mode, uint64_t frames, int64_t period_ns, uint64_t iterations,
                  const std::string& trace_path = "") {
  CountingSource source(frames, period_ns);
  WorkStage extract("extract", iterations), track("track", iterations / 2), map("map", iterations / 2);
  RunOptions options;
  options.mode = mode;
  options.slot_count = 4;
  StageRunner<WorkFrame> runner(source, {&extract, &track, &map}, options);
  const Status status = runner.run();
  if (!status.ok()) std::fprintf(stderr, "run failed: %s\n", status.message().c_str());
  if (!trace_path.empty()) {
    const Status written = writeChromeTrace(trace_path, runner.trace(), runner.report());
    std::printf("%s\n", written.ok() ? ("trace: " + trace_path).c_str() : written.message().c_str());
  }
  return runner.report();
}

}  // namespace
}  // namespace plumb::runtime

int main(int argc, char** argv) {
  using namespace plumb::runtime;
  std::string trace_path;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--trace") && i + 1 < argc) trace_path = argv[++i];
  }
  std::printf("SpscRing<uint64_t> hand-off: %.1f M items/s\n", ringItemsPerSecond(20'000'000) * 1e-6);

  // Calibrate: ~4 ms of work per frame in total (extract 2 ms, track 1 ms, map 1 ms).
  const uint64_t probe = 2'000'000;
  const int64_t t0 = plumb::monotonicNowNs();
  runWork(RunMode::kDeterministic, 5, 0, probe);
  const double ns_per_iteration = static_cast<double>(plumb::monotonicNowNs() - t0) / (5 * 2.0 * probe);
  const auto iterations = static_cast<uint64_t>(2e6 / ns_per_iteration);

  const RunReport single = runWork(RunMode::kDeterministic, 300, 0, iterations);
  const RunReport fast = runWork(RunMode::kFast, 300, 0, iterations);
  std::printf("\nsingle-threaded (lock-step):\n%s", formatRunReport(single).c_str());
  std::printf("\nfast (threads):\n%s", formatRunReport(fast).c_str());
  std::printf("fast / single-threaded: %.2fx frames per second\n",
              fast.framesPerSecond() / single.framesPerSecond());

  const RunReport realtime = runWork(RunMode::kRealtime, 150, 33'333'333, iterations, trace_path);
  std::printf("\nrealtime at 30 Hz:\n%s", formatRunReport(realtime).c_str());
  std::printf("realtime p99 end-to-end %.2f ms, %llu dropped\n",
              static_cast<double>(realtime.end_to_end.percentileNs(0.99)) * 1e-6,
              static_cast<unsigned long long>(realtime.frames_dropped));
  return 0;
}

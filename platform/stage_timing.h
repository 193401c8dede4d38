#pragma once
// Timing of processing stages: wall milliseconds since a steady-clock instant and the calling
// thread's CPU time (the front end's per-stage timings, `plumb bench`, bench/), and a series of
// per-frame times summarised by percentiles (the benchmarks' tables). Latencies between threads
// and pacing use monotonic_time.h.
#include <chrono>
#include <vector>

namespace plumb {

using StageClock = std::chrono::steady_clock;

// Wall milliseconds from `start` to now.
double msSince(StageClock::time_point start);

// CPU time the calling thread has used, in milliseconds (CLOCK_THREAD_CPUTIME_ID).
double threadCpuMs();

// Per-frame times of one stage.
struct TimingSeries {
  const char* name;
  std::vector<double> ms;

  // The p-quantile (0..1) by nearest rank of the sorted times; 0 for an empty series.
  double percentile(double p) const;
  // "  <name padded to name_width> median X ms   p99 Y ms" on stdout.
  void print(int name_width) const;
};

}  // namespace plumb

#include "platform/stage_timing.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>

namespace plumb {

double msSince(StageClock::time_point start) {
  return std::chrono::duration<double, std::milli>(StageClock::now() - start).count();
}

double threadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

double TimingSeries::percentile(double p) const {
  if (ms.empty()) return 0;
  std::vector<double> sorted = ms;
  std::sort(sorted.begin(), sorted.end());
  const size_t i = std::min(sorted.size() - 1, static_cast<size_t>(std::llround(p * double(sorted.size() - 1))));
  return sorted[i];
}

void TimingSeries::print(int name_width) const {
  std::printf("  %-*s median %7.2f ms   p99 %7.2f ms\n", name_width, name, percentile(0.5), percentile(0.99));
}

}  // namespace plumb

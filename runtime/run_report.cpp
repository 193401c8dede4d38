#include "runtime/run_report.h"

#include <cstdio>

namespace plumb::runtime {

namespace {

double ms(int64_t ns) { return static_cast<double>(ns) * 1e-6; }

void appendRow(std::string* out, const std::string& name, const LatencyHistogram& h) {
  char line[160];
  std::snprintf(line, sizeof(line), "%-14s %7llu %9.3f %9.3f %9.3f %9.3f %9.3f\n", name.c_str(),
                static_cast<unsigned long long>(h.count()), ms(h.percentileNs(0.50)),
                ms(h.percentileNs(0.90)), ms(h.percentileNs(0.99)), ms(h.maxNs()),
                h.meanNs() * 1e-6);
  *out += line;
}

}  // namespace

std::string formatRunReport(const RunReport& report) {
  std::string out;
  char line[200];
  std::snprintf(line, sizeof(line), "%-14s %7s %9s %9s %9s %9s %9s\n", "stage", "frames",
                "p50 ms", "p90 ms", "p99 ms", "max ms", "mean ms");
  out += line;
  for (const StageReport& stage : report.stages) appendRow(&out, stage.name, stage.latency);
  appendRow(&out, "end-to-end", report.end_to_end);
  const int e2e = report.end_to_end_stage;
  if (e2e > 0 && e2e + 1 < static_cast<int>(report.stages.size())) {
    std::snprintf(line, sizeof(line), "end-to-end = sensor time to '%s' done (later stages not included)\n",
                  report.stages[e2e].name.c_str());
    out += line;
  }
  std::snprintf(line, sizeof(line),
                "mode %s: %llu frames read, %llu completed, %llu dropped (no free slot), %llu late "
                "(source behind), %.3f s, %.2f frames/s\n",
                report.mode.c_str(), static_cast<unsigned long long>(report.frames_read),
                static_cast<unsigned long long>(report.frames_completed),
                static_cast<unsigned long long>(report.frames_dropped),
                static_cast<unsigned long long>(report.frames_late), ms(report.wall_ns) * 1e-3,
                report.framesPerSecond());
  out += line;
  return out;
}

}  // namespace plumb::runtime

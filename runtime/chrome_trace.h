#pragma once
// Chrome trace-event export of a pipeline run, and reading it back (`plumb profile`).
//
// The file is the JSON object form of the trace-event format, which Perfetto (ui.perfetto.dev)
// and chrome://tracing open directly:
//   - one track (tid) per stage, named by "thread_name" metadata; tid 0 = the source;
//   - a complete event ("ph":"X", ts/dur in microseconds) per stage step, args {"frame": n};
//   - an instant event ("ph":"i") on the source track per frame not processed: "drop" (no free
//     slot) or "late" (the source was too far behind the frame's due time);
//   - an async span ("ph":"b"/"e", cat "end_to_end", id = frame) from sensor time to the last
//     stage's completion, so end-to-end latency shows as its own row;
//   - "otherData": mode and frame counters (read, completed, dropped, wall time).
// Times are relative to the earliest recorded time, so the numbers stay small and readable.
#include <string>
#include <vector>

#include "platform/status.h"
#include "runtime/run_report.h"
#include "runtime/trace_log.h"

namespace plumb::runtime {

// Writes the whole trace at once (after the run; never on the hot path).
Status writeChromeTrace(const std::string& path, const std::vector<TraceTrack>& tracks,
                        const RunReport& report);
// Same text, returned as a string (tests, and writing to other sinks).
std::string formatChromeTrace(const std::vector<TraceTrack>& tracks, const RunReport& report);

// Rebuilds the report (per-stage and end-to-end histograms, counters) from a trace file written by
// writeChromeTrace. Errors name the file.
Status readChromeTrace(const std::string& path, RunReport* report);
Status parseChromeTrace(const std::string& text, RunReport* report);

}  // namespace plumb::runtime

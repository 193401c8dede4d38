#pragma once
// Resident memory of this process, for memory checkpoints in statistics and benchmarks.

namespace plumb {

// Peak (VmHWM) and current (VmRSS) resident set size in KiB, from /proc/self/status. false when
// the file cannot be read (then both are -1).
bool readRss(long* peak_kib, long* current_kib);

}  // namespace plumb

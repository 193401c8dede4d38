#pragma once
// Monotonic nanosecond time. Every latency in plumb is a difference of two of these values, so it
// must never jump (CLOCK_MONOTONIC: unaffected by NTP steps or the user setting the date).
#include <cstdint>

namespace plumb {

// Nanoseconds since an arbitrary fixed point (boot on Linux). Never decreases.
int64_t monotonicNowNs();

// Sleeps until monotonicNowNs() >= t_ns (absolute deadline, so repeated pacing does not drift).
// Returns at once when the deadline has passed. Restarts after signals.
void sleepUntilMonotonicNs(int64_t t_ns);

}  // namespace plumb

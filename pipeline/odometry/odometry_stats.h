#pragma once
// Counters of a run of the odometry system (reported by `plumb run --stats`).
#include <cstdint>

namespace plumb {

struct OdometryStats {
  uint64_t frames = 0;
  uint64_t frames_ok = 0;
  uint64_t frames_weak = 0;
  uint64_t frames_lost = 0;             // no pose output
  uint64_t frames_not_initialized = 0;  // before the first map
  uint64_t frames_motion_fallback = 0;  // constant velocity failed, wide/zero-motion retry used
  uint64_t keyframes = 0;
  uint64_t relocalizations = 0;
  uint64_t relocalization_attempts = 0;
  uint64_t segments = 0;                // maps started (1 = never restarted)
  // Frames the output queue could not take because the caller did not drain it (never with the
  // runner, which drains after every frame): counted, never silently overwritten.
  uint64_t output_overflows = 0;
  uint64_t loop_corrections_applied = 0;  // loop closing moved the local map
  uint64_t loop_corrections_stale = 0;    // its keyframe had left the map: not applied
  // A run that started in a loaded map (--load-map): the 0-based index of the frame that
  // relocalized into it (-1: not a loaded-map run, or never relocalized).
  int64_t loaded_map_relocalized_frame = -1;
  uint64_t loaded_map_keyframes = 0;  // keyframes the relocalizer got from the loaded map
};

}  // namespace plumb

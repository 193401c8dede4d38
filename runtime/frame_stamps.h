#pragma once
// FrameStamps: the timing every frame slot carries through the pipeline (PX4-style: the time the
// data was sensed, separate from the times it was processed). Latency is then a subtraction:
// stage k took t_done_ns[k] - t_start_ns[k]; end to end is t_done_ns[last] - t_sensor_ns.
// Stage 0 is the source (capture); stages 1..N are the processing stages in pipeline order.
#include <array>
#include <cstdint>

namespace plumb::runtime {

// Source plus at most 7 processing stages (capture -> extract -> track -> map needs 4).
inline constexpr int kMaxStages = 8;

struct FrameStamps {
  uint64_t frame_index = 0;   // position in the source stream; dropped frames use up an index too
  int64_t t_recorded_ns = 0;  // the frame's own timestamp (recording / device clock)
  int64_t t_sensor_ns = 0;    // runtime-clock time the frame existed: the pacing target in replay,
                              // the capture start otherwise
  std::array<int64_t, kMaxStages> t_start_ns{};
  std::array<int64_t, kMaxStages> t_done_ns{};
};

}  // namespace plumb::runtime

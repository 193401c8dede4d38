#pragma once
// Compile-time capacities of the odometry map. Everything the map and its snapshots hold lives in
// arrays of these sizes, allocated once when the system starts; when one is full the oldest or
// worst entry is retired, so memory stays flat however long the system runs.
#include <cstddef>
#include <cstdint>

#include "pipeline/frontend/capacities.h"

namespace plumb {

// Keyframes kept with their observations (the local-BA window is chosen among them). A landmark
// records which of these slots observe it in a 32-bit mask, hence the limit of 32.
constexpr std::size_t kMaxMapKeyframes = 32;
using KeyframeMask = uint32_t;
static_assert(kMaxMapKeyframes <= 8 * sizeof(KeyframeMask), "one mask bit per keyframe slot");

constexpr std::size_t kMaxMapPoints = 8000;  // point landmarks
constexpr std::size_t kMaxMapLines = 1500;   // line landmarks (each = up to kMaxLineSamples points)

// What one LocalMap snapshot (the tracker's view of the map) can carry.
constexpr std::size_t kMaxLocalMapPoints = 4000;
constexpr std::size_t kMaxLocalMapLines = 600;

// Keyframes remembered for relocalization only (pose + descriptors + 3D points in camera frame),
// a ring independent of the map window: the last 100 keyframes (~3 local maps; 22 KB each, 2.2 MB,
// resident from start). It was 200 (4.4 MB) until the memory budget of issue 14: the long-term
// memory of places is the loop closer's keyframe graph (docs/LOOP.md).
constexpr std::size_t kMaxRelocKeyframes = 100;
constexpr std::size_t kMaxRelocFeatures = 500;

}  // namespace plumb

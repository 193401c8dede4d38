#pragma once
// Compile-time capacities of every per-frame container. Frame slots are sized from these once at
// start-up; nothing per frame grows past them (a full container drops the weakest and counts it).
#include <cstddef>

namespace plumb {

constexpr std::size_t kMaxKeypoints = 1200;   // ORB target is ~1000 per 640x480 frame
constexpr std::size_t kMaxLines = 200;        // LSD segments kept per frame (default keeps 150)
constexpr std::size_t kMaxLineSamples = 10;   // line-guidance samples per line (paper: 5)
constexpr int kPyramidLevels = 8;             // ORB pyramid, scale factor 1.2

}  // namespace plumb

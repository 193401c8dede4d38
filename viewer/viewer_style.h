#pragma once
// How the viewer draws things, in one place for the live and the after-the-run views (and the
// page's legend, viewer/web/index.html, which names the same colours).
#include "viewer/foxglove_messages.h"

namespace plumb::viewer {

inline constexpr float kFrustumDepthM = 0.08f;  // keyframe and camera pyramids
inline constexpr Rgba kOutputColor{0.20f, 0.80f, 0.35f, 1.0f};     // final poses (the file's)
inline constexpr Rgba kTrackedColor{1.00f, 0.60f, 0.10f, 1.0f};    // as tracked, not final yet
inline constexpr Rgba kGroundTruthColor{0.75f, 0.75f, 0.78f, 1.0f};
inline constexpr Rgba kLoopColor{0.95f, 0.25f, 0.85f, 1.0f};
inline constexpr Rgba kLineColor{0.30f, 0.85f, 0.95f, 1.0f};       // line landmarks
inline constexpr Rgba kKeyframeColor{0.35f, 0.50f, 1.00f, 0.8f};
inline constexpr Rgba kLocalKeyframeColor{1.00f, 1.00f, 1.00f, 1.0f};  // in the local map now

}  // namespace plumb::viewer

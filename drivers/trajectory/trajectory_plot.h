#pragma once
// Evaluation plot drawn with OpenCV: top panel, a top view (the plane of the two largest extents
// of the ground truth) of ground truth vs aligned estimate; bottom panel, x/y/z error of the
// aligned estimate over time. Axes with ticks and labels in metres / seconds.
#include <string>

#include "drivers/trajectory/evaluate.h"
#include "platform/status.h"

namespace plumb {

struct TrajectoryPlotOptions {
  int width_px = 1000;
  int height_px = 1100;  // top view ~ 2/3, error panel ~ 1/3
  std::string title;     // e.g. "ATE RMSE 0.0135 m over 786 pairs"
};

// Writes a PNG; error names the file when the path is not writable.
Status writeTrajectoryPlot(const std::string& png_path, const AteResult& ate,
                           const TrajectoryPlotOptions& options = {});

}  // namespace plumb

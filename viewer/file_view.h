#pragma once
// FileView: what `plumb view` serves (docs/VIEWER.md): a finished run from its files, on the same
// channels as a live run (viewer/viewer_channels.h), every message latched so a client that
// connects at any time gets all of it.
//   --out TRAJ     the estimate (foxglove.SceneUpdate strips, broken at lost/dropped frames)
//   --gt GT        ground truth beside it: the estimate aligned to it (the ATE's rigid alignment,
//                  drivers/trajectory/evaluate.h) and coloured by each pose's error, green (0) to
//                  red (the largest error); ground truth in grey
//   --map M.map    keyframe frusta, loop edges, and the keyframes' 3D points and line segments
//   --stats S.json the run's numbers on the status channel
#include <string>
#include <vector>

#include "drivers/trajectory/trajectory_io.h"
#include "pipeline/loop/saved_map.h"
#include "platform/status.h"
#include "viewer/foxglove_server.h"

namespace plumb::viewer {

struct FileViewInput {
  std::vector<StampedPose> estimate;
  std::vector<StampedPose> ground_truth;  // empty: none
  const loop::SavedMap* map = nullptr;    // nullptr: none
  std::string stats_json;                 // '' : none
  std::string title;                      // what the status channel names as the source
};

struct FileViewSummary {
  std::size_t estimate_poses = 0;  // valid poses drawn
  std::size_t ground_truth_poses = 0;
  double ate_rmse_m = -1;  // -1: no ground truth (or too few pairs)
  double error_max_m = 0;
  std::size_t map_keyframes = 0, map_points = 0, map_lines = 0, loop_edges = 0;
};

class FileView {
 public:
  // Builds every message once. Errors: a stats file that is not JSON.
  Status build(const FileViewInput& input, FileViewSummary* summary);
  // Server thread: the first call publishes everything; later ones only the status (clients).
  void tick(FoxgloveServer& server);

 private:
  std::vector<std::pair<std::size_t, std::string>> messages_;  // channel, JSON
  std::string status_prefix_;  // the status object without its closing brace and the clients count
  double timestamp_s_ = 0;
  bool published_ = false;
  int ticks_ = 0;
};

}  // namespace plumb::viewer

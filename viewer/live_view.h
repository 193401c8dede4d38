#pragma once
// LiveView: the server thread's side of `plumb run --serve` (docs/VIEWER.md). Each tick it drains
// the RunFeed (viewer/run_feed.h) and publishes the viewer channels (viewer/viewer_channels.h):
//   per frame:   camera pose + /tf (each tracked frame), output pose (each trajectory-file line)
//   rate-bound:  trajectory, loops, map points and lines, keyframes (at most every
//                geometry_interval_s, when changed); status (every status_interval_s); the image
//                (when a new one arrived and someone is subscribed)
// All of it on the server thread, which allocates freely (it is not on the frame path).
#include <atomic>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "runtime/latency_histogram.h"
#include "viewer/foxglove_messages.h"
#include "viewer/foxglove_server.h"
#include "viewer/run_feed.h"

namespace plumb::viewer {

struct LiveViewOptions {
  std::string mode;    // the run's mode, for the status channel
  std::string source;  // what the run reads, for the status channel
  double geometry_interval_s = 0.5;
  double status_interval_s = 0.2;
  int jpeg_quality = 75;
};

class LiveView {
 public:
  LiveView(RunFeed& feed, FoxgloveServer& server, LiveViewOptions options);

  // Server thread: the FoxgloveServer's tick.
  void tick();
  // Any thread, before FoxgloveServer::stop(): the final tick then publishes everything at once
  // and says "ended".
  void markEnded() { ended_.store(true, std::memory_order_release); }

  // Read after the server stopped.
  uint64_t framesSeen() const { return frames_; }
  uint64_t outputPosesPublished() const { return output_poses_; }

 private:
  struct TrackPoint {
    double timestamp_s;
    Eigen::Vector3f position;
  };
  void drainFrames();
  void drainFinished();
  void drainLoops();
  void takeMap();
  void publishImage();
  void publishTrajectory();
  void publishLoops();
  void publishMap();
  void publishStatus();
  bool due(double last_s, double interval_s) const;
  double nowS() const;

  RunFeed& feed_;
  FoxgloveServer& server_;
  LiveViewOptions options_;
  std::atomic<bool> ended_{false};
  bool final_ = false;  // this tick is the final one

  // Trajectory: the output (final) poses in strips broken at lost / dropped frames, and the
  // tracked poses newer than the last final one.
  std::vector<std::vector<Eigen::Vector3f>> output_strips_{1};
  double last_output_timestamp_s_ = -1e300;
  std::vector<TrackPoint> tracked_tail_;
  std::vector<FeedLoop> loops_;
  std::vector<Eigen::Vector3f> map_points_;
  std::vector<Eigen::Vector3f> map_lines_;  // line list
  std::map<uint32_t, FeedKeyframe> keyframes_;  // every keyframe seen, newest pose seen
  std::vector<uint32_t> local_keyframes_;
  uint64_t map_version_ = 0, image_version_ = 0;
  bool trajectory_dirty_ = false, loops_dirty_ = false, map_dirty_ = false;
  double trajectory_sent_s_ = -1e300, loops_sent_s_ = -1e300, map_sent_s_ = -1e300, status_sent_s_ = -1e300;

  // Status.
  FeedFrame last_frame_;
  double last_timestamp_s_ = 0;
  uint64_t frames_ = 0, dropped_ = 0, lost_ = 0, keyframes_seen_ = 0, relocalizations_ = 0, output_poses_ = 0;
  runtime::LatencyHistogram latency_window_;  // the current second
  double latency_window_start_s_ = 0;
  double latency_p99_ms_ = -1;  // of the last full second
  std::vector<uint8_t> jpeg_;
};

// The trajectory strips as line-strip primitives of one colour, thinned to at most max_points
// (every k-th point; each strip keeps its last point so the newest pose is always drawn).
void appendStrips(const std::vector<std::vector<Eigen::Vector3f>>& strips, const Rgba& color, double thickness_px,
                  std::size_t max_points, std::vector<LinePrimitive>* out);

}  // namespace plumb::viewer

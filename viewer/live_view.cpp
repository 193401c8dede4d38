#include "viewer/live_view.h"

#include <chrono>
#include <cmath>

#include "drivers/image/jpeg_encoder.h"
#include "viewer/json_writer.h"
#include "viewer/viewer_channels.h"
#include "viewer/viewer_style.h"

namespace plumb::viewer {
namespace {

constexpr std::size_t kMaxLiveTrajectoryPoints = 6000;  // per message: ~200 KB of JSON at most
constexpr std::size_t kMaxKeyframesDrawn = 400;     // the newest ones

uint64_t toNs(double seconds) { return seconds > 0 ? uint64_t(std::llround(seconds * 1e9)) : 0; }

const char* stateName(const FeedFrame& f) {
  if (f.dropped) return "dropped";
  switch (f.state) {
    case TrackingState::kOk: return "ok";
    case TrackingState::kWeak: return "weak";
    case TrackingState::kLost: return "lost";
    default: return "not_initialized";
  }
}

}  // namespace

void appendStrips(const std::vector<std::vector<Eigen::Vector3f>>& strips, const Rgba& color, double thickness_px,
                  std::size_t max_points, std::vector<LinePrimitive>* out) {
  std::size_t total = 0;
  for (const auto& s : strips) total += s.size();
  const std::size_t step = total > max_points ? (total + max_points - 1) / max_points : 1;
  for (const auto& s : strips) {
    if (s.size() < 2) continue;
    LinePrimitive line;
    line.type = LinePrimitive::kStrip;
    line.color = color;
    line.thickness_px = thickness_px;
    for (std::size_t i = 0; i < s.size(); i += step) line.points.push_back(s[i]);
    if ((s.size() - 1) % step != 0) line.points.push_back(s.back());
    out->push_back(std::move(line));
  }
}

LiveView::LiveView(RunFeed& feed, FoxgloveServer& server, LiveViewOptions options)
    : feed_(feed), server_(server), options_(std::move(options)) {}

double LiveView::nowS() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

bool LiveView::due(double last_s, double interval_s) const { return final_ || nowS() - last_s >= interval_s; }

void LiveView::tick() {
  final_ = ended_.load(std::memory_order_acquire);
  drainFrames();
  drainFinished();
  drainLoops();
  takeMap();
  publishImage();
  if (trajectory_dirty_ && due(trajectory_sent_s_, options_.geometry_interval_s)) publishTrajectory();
  if (loops_dirty_ && due(loops_sent_s_, options_.geometry_interval_s)) publishLoops();
  if (map_dirty_ && due(map_sent_s_, options_.geometry_interval_s)) publishMap();
  if (due(status_sent_s_, options_.status_interval_s)) publishStatus();
}

void LiveView::drainFrames() {
  FeedFrame f;
  while (feed_.popFrame(&f)) {
    ++frames_;
    last_frame_ = f;
    last_timestamp_s_ = f.timestamp_s;
    if (f.dropped) {
      ++dropped_;
      continue;
    }
    lost_ += !f.has_pose;
    keyframes_seen_ += f.keyframe;
    relocalizations_ += f.relocalized;
    if (f.latency_ms >= 0) latency_window_.add(int64_t(f.latency_ms * 1e6));
    if (!f.has_pose) continue;
    const uint64_t t_ns = toNs(f.timestamp_s);
    server_.publish(kCameraPose, t_ns, poseInFrameJson(f.timestamp_s, f.t_world_cam, f.q_world_cam));
    server_.publish(kCameraTransform, t_ns, frameTransformJson(f.timestamp_s, f.t_world_cam, f.q_world_cam));
    tracked_tail_.push_back({f.timestamp_s, f.t_world_cam.cast<float>()});
    trajectory_dirty_ = true;
  }
}

void LiveView::drainFinished() {
  FeedFinishedPose p;
  while (feed_.popFinishedPose(&p)) {
    last_output_timestamp_s_ = p.timestamp_s;
    trajectory_dirty_ = true;
    if (!p.valid) {
      if (!output_strips_.back().empty()) output_strips_.emplace_back();
      continue;
    }
    output_strips_.back().push_back(p.t_world_cam.cast<float>());
    server_.publish(kOutputPose, toNs(p.timestamp_s), poseInFrameJson(p.timestamp_s, p.t_world_cam, p.q_world_cam));
    ++output_poses_;
  }
  // The tail: tracked poses the output has not reached yet (the output lags by --output-delay).
  std::size_t keep_from = 0;
  while (keep_from < tracked_tail_.size() && tracked_tail_[keep_from].timestamp_s <= last_output_timestamp_s_) {
    ++keep_from;
  }
  if (keep_from > 0) tracked_tail_.erase(tracked_tail_.begin(), tracked_tail_.begin() + long(keep_from));
}

void LiveView::drainLoops() {
  FeedLoop loop;
  while (feed_.popLoop(&loop)) {
    loops_.push_back(loop);
    loops_dirty_ = true;
  }
}

void LiveView::takeMap() {
  uint64_t version = 0;
  const FeedMap* map = feed_.latestMap(&version);
  if (map == nullptr || version == map_version_) return;
  map_version_ = version;
  map_points_.assign(map->points_world.begin(), map->points_world.begin() + long(map->point_count));
  map_lines_.clear();
  for (std::size_t i = 0; i < map->line_count; ++i) {
    map_lines_.push_back(map->lines_world[i].start);
    map_lines_.push_back(map->lines_world[i].end);
  }
  local_keyframes_.clear();
  for (std::size_t i = 0; i < map->keyframe_count; ++i) {
    keyframes_[map->keyframes[i].id] = map->keyframes[i];
    local_keyframes_.push_back(map->keyframes[i].id);
  }
  map_dirty_ = true;
}

void LiveView::publishImage() {
  uint64_t version = 0;
  const FeedImage* image = feed_.latestImage(&version);
  if (image == nullptr || version == image_version_) return;
  image_version_ = version;
  if (!server_.hasSubscribers(kImage)) return;  // JPEG costs this thread ~1 ms: only for a watcher
  std::string error;
  if (!encodeJpeg(image->bgr.data(), image->width, image->height, std::size_t(image->width) * 3,
                  options_.jpeg_quality, &jpeg_, &error)) {
    return;
  }
  server_.publish(kImage, toNs(image->timestamp_s), compressedImageJson(image->timestamp_s, jpeg_));
}

void LiveView::publishTrajectory() {
  trajectory_dirty_ = false;
  trajectory_sent_s_ = nowS();
  LineEntity output{"output", {}};
  appendStrips(output_strips_, kOutputColor, 4, kMaxLiveTrajectoryPoints, &output.lines);
  LineEntity tracked{"tracked", {}};
  std::vector<std::vector<Eigen::Vector3f>> tail(1);
  // The tail starts at the newest output pose, so the two lines join.
  if (!output_strips_.back().empty()) tail[0].push_back(output_strips_.back().back());
  for (const TrackPoint& p : tracked_tail_) tail[0].push_back(p.position);
  appendStrips(tail, kTrackedColor, 4, kMaxLiveTrajectoryPoints, &tracked.lines);
  server_.publish(kTrajectory, toNs(last_timestamp_s_), sceneUpdateJson(last_timestamp_s_, {output, tracked}));
}

void LiveView::publishLoops() {
  loops_dirty_ = false;
  loops_sent_s_ = nowS();
  LineEntity entity{"loops", {}};
  LinePrimitive edges;
  edges.type = LinePrimitive::kList;
  edges.color = kLoopColor;
  edges.thickness_px = 3;
  for (const FeedLoop& l : loops_) {
    edges.points.push_back(l.query_position.cast<float>());
    edges.points.push_back(l.candidate_position.cast<float>());
  }
  entity.lines.push_back(std::move(edges));
  server_.publish(kLoops, toNs(last_timestamp_s_), sceneUpdateJson(last_timestamp_s_, {entity}));
}

void LiveView::publishMap() {
  map_dirty_ = false;
  map_sent_s_ = nowS();
  const uint64_t t_ns = toNs(last_timestamp_s_);
  server_.publish(kMapPoints, t_ns, pointCloudJson(last_timestamp_s_, map_points_));
  LineEntity lines{"map_lines", {}};
  LinePrimitive segments;
  segments.type = LinePrimitive::kList;
  segments.color = kLineColor;
  segments.thickness_px = 1.5;
  segments.points = map_lines_;
  lines.lines.push_back(std::move(segments));
  server_.publish(kMapLines, t_ns, sceneUpdateJson(last_timestamp_s_, {lines}));

  LineEntity frusta{"keyframes", {}};
  LinePrimitive old_frusta, local_frusta;
  old_frusta.type = local_frusta.type = LinePrimitive::kList;
  old_frusta.color = kKeyframeColor;
  local_frusta.color = kLocalKeyframeColor;
  old_frusta.thickness_px = local_frusta.thickness_px = 1;
  std::size_t skip = keyframes_.size() > kMaxKeyframesDrawn ? keyframes_.size() - kMaxKeyframesDrawn : 0;
  for (const auto& [id, k] : keyframes_) {
    if (skip > 0) {
      --skip;
      continue;
    }
    bool local = false;
    for (uint32_t l : local_keyframes_) local = local || l == id;
    appendFrustum(k.t_world_cam, k.q_world_cam, kFrustumDepthM, local ? &local_frusta.points : &old_frusta.points);
  }
  frusta.lines.push_back(std::move(old_frusta));
  frusta.lines.push_back(std::move(local_frusta));
  server_.publish(kKeyframes, t_ns, sceneUpdateJson(last_timestamp_s_, {frusta}));
}

void LiveView::publishStatus() {
  status_sent_s_ = nowS();
  // p99 over the last second (or what the final tick has).
  if (latency_window_.count() > 0 && (final_ || status_sent_s_ - latency_window_start_s_ >= 1.0)) {
    latency_p99_ms_ = double(latency_window_.percentileNs(0.99)) * 1e-6;
    latency_window_.clear();
    latency_window_start_s_ = status_sent_s_;
  }
  const FoxgloveServerStats s = server_.stats();
  JsonWriter w;
  w.beginObject();
  w.key("timestamp").beginObject();
  w.key("sec").number(uint64_t(std::max(0.0, std::floor(last_timestamp_s_))));
  w.key("nsec").number(uint64_t(std::llround((last_timestamp_s_ - std::floor(last_timestamp_s_)) * 1e9) % 1000000000));
  w.endObject();
  w.key("mode").string(options_.mode);
  w.key("source").string(options_.source);
  w.key("state").string(final_ ? "ended" : frames_ == 0 ? "not_initialized" : stateName(last_frame_));
  w.key("frame").number(last_frame_.sequence);
  w.key("frame_timestamp").number(last_frame_.timestamp_s);
  w.key("frames").number(frames_);
  w.key("keyframes").number(keyframes_seen_);
  w.key("point_inliers").number(last_frame_.point_inliers);
  w.key("line_inliers").number(last_frame_.line_inliers);
  w.key("landmark_inliers").number(last_frame_.landmark_inliers);
  w.key("latency_ms").number(last_frame_.latency_ms, 4);
  w.key("latency_p99_ms").number(latency_p99_ms_, 4);
  w.key("frames_dropped").number(dropped_);
  w.key("frames_lost").number(lost_);
  w.key("loops").number(uint64_t(loops_.size()));
  w.key("relocalizations").number(relocalizations_);
  w.key("map_points").number(uint64_t(map_points_.size()));
  w.key("map_lines").number(uint64_t(map_lines_.size() / 2));
  w.key("viewer_records_dropped").number(feed_.recordsDropped());
  w.key("viewer_messages_dropped").number(s.messages_dropped);
  w.key("clients").number(uint64_t(server_.clientCount()));
  w.endObject();
  server_.publish(kStatus, toNs(last_timestamp_s_), w.text());
}

}  // namespace plumb::viewer

#include "viewer/viewer_sink.h"

#include <algorithm>

#include "platform/monotonic_time.h"

namespace plumb::viewer {

void ViewerSink::onPose(const FrameOutput& frame) {
  inner_.onPose(frame);
  if (frame.t_sensor_ns > 0) feed_.recordLatency(frame.sequence, monotonicNowNs() - frame.t_sensor_ns);
}

Status ViewerSink::onFrame(const FrameOutput& out) {
  const Status status = inner_.onFrame(out);
  FeedFrame f;
  f.sequence = out.sequence;
  f.timestamp_s = out.timestamp_s;
  f.dropped = out.dropped;
  if (!out.dropped) {
    f.state = out.state;
    f.has_pose = out.has_pose;
    f.keyframe = out.keyframe;
    f.relocalized = out.relocalized;
    f.new_map = out.new_map;
    f.t_world_cam = out.T_world_cam.translation();
    f.q_world_cam = Eigen::Quaterniond(out.T_world_cam.rotation());
    f.point_inliers = out.track.point_inliers;
    f.line_inliers = out.track.line_inliers;
    f.landmark_inliers = out.track.landmark_inliers;
    f.extract_ms = out.extract_ms;
    f.track_ms = out.track_ms;
    f.map_ms = out.map_ms;
  }
  feed_.pushFrame(f);
  return status;
}

Status ViewerSink::onFinishedFrame(const FinishedFrame& frame) {
  const Status status = inner_.onFinishedFrame(frame);
  FeedFinishedPose p;
  p.timestamp_s = frame.timestamp_s;
  p.valid = frame.valid;
  p.dropped = frame.dropped;
  p.t_world_cam = frame.T_world_cam.translation();
  p.q_world_cam = Eigen::Quaterniond(frame.T_world_cam.rotation());
  feed_.pushFinishedPose(p);
  return status;
}

void ViewerSink::onFrameView(const FrameView& view) {
  inner_.onFrameView(view);
  if (view.local_map.version != map_version_seen_) copyMap(view);
  if (view.stats.loop_corrections_applied != loops_seen_) {
    loops_seen_ = view.stats.loop_corrections_applied;
    const MapCorrection& c = view.last_loop_correction;
    if (c.loop_candidate_id != 0) {
      FeedLoop loop;
      loop.timestamp_s = view.output.timestamp_s;
      loop.query_id = c.keyframe_id;
      loop.candidate_id = c.loop_candidate_id;
      loop.query_position = c.T_world_cam.translation();
      loop.candidate_position = c.T_world_candidate.translation();
      feed_.pushLoop(loop);
    }
  }
  const int64_t interval = feed_.imageIntervalNs();
  if (interval > 0) {
    const int64_t now = monotonicNowNs();
    if (now - last_image_ns_ >= interval) {
      last_image_ns_ = now;
      copyImage(view);
    }
  }
}

void ViewerSink::copyMap(const FrameView& view) {
  const LocalMap& map = view.local_map;
  map_version_seen_ = map.version;
  FeedMap& m = feed_.mapWriteBuffer();
  m.frame_sequence = view.output.sequence;
  m.timestamp_s = view.output.timestamp_s;
  m.point_count = std::min(map.points.size(), m.points_world.size());
  for (std::size_t i = 0; i < m.point_count; ++i) m.points_world[i] = map.points[i].P_world.cast<float>();
  m.line_count = std::min(map.lines.size(), m.lines_world.size());
  for (std::size_t i = 0; i < m.line_count; ++i) {
    m.lines_world[i].start = map.lines[i].start_world.cast<float>();
    m.lines_world[i].end = map.lines[i].end_world.cast<float>();
  }
  m.keyframe_count = std::min(map.keyframes.size(), m.keyframes.size());
  for (std::size_t i = 0; i < m.keyframe_count; ++i) {
    const LocalMapKeyframe& k = map.keyframes[i];
    m.keyframes[i].id = k.id;
    m.keyframes[i].t_world_cam = k.T_world_cam.translation().cast<float>();
    m.keyframes[i].q_world_cam = Eigen::Quaternionf(k.T_world_cam.rotation().cast<float>());
  }
  feed_.publishMap(map.version);
}

void ViewerSink::copyImage(const FrameView& view) {
  FeedImage& image = feed_.imageWriteBuffer();
  if (!downscaleInto(view.image.bgr, &image)) return;
  image.sequence = view.output.sequence;
  image.timestamp_s = view.output.timestamp_s;
  feed_.publishImage(++images_published_);
}

bool downscaleInto(const cv::Mat& bgr, FeedImage* out) {
  if (bgr.empty() || bgr.type() != CV_8UC3) return false;
  int factor = 1;
  while (bgr.cols / factor > FeedImage::kMaxWidth || bgr.rows / factor > FeedImage::kMaxHeight) ++factor;
  const int width = bgr.cols / factor, height = bgr.rows / factor;
  if (width < 1 || height < 1) return false;
  const int area = factor * factor;
  for (int y = 0; y < height; ++y) {
    uint8_t* dst = out->bgr.data() + std::size_t(y) * std::size_t(width) * 3;
    for (int x = 0; x < width; ++x) {
      int sum[3] = {0, 0, 0};
      for (int dy = 0; dy < factor; ++dy) {
        const uint8_t* src = bgr.ptr<uint8_t>(y * factor + dy) + std::size_t(x) * std::size_t(factor) * 3;
        for (int dx = 0; dx < factor; ++dx, src += 3) {
          sum[0] += src[0];
          sum[1] += src[1];
          sum[2] += src[2];
        }
      }
      for (int c = 0; c < 3; ++c) dst[x * 3 + c] = uint8_t((sum[c] + area / 2) / area);
    }
  }
  out->width = width;
  out->height = height;
  return true;
}

}  // namespace plumb::viewer

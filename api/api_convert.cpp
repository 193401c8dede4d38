#include "api/api_convert.h"

namespace plumb::api {

CameraValues toValues(const PinholeCamera& c) {
  CameraValues v;
  v.fx = c.fx, v.fy = c.fy, v.cx = c.cx, v.cy = c.cy;
  v.k1 = c.k1, v.k2 = c.k2, v.p1 = c.p1, v.p2 = c.p2, v.k3 = c.k3;
  v.width = c.width, v.height = c.height;
  v.depth_factor = c.depth_factor;
  v.baseline_m = c.baseline_m;
  v.rolling_shutter_readout_s = c.rolling_shutter_readout_s;
  return v;
}

PinholeCamera toCamera(const CameraValues& v) {
  PinholeCamera c;
  c.fx = v.fx, c.fy = v.fy, c.cx = v.cx, c.cy = v.cy;
  c.k1 = v.k1, c.k2 = v.k2, c.p1 = v.p1, c.p2 = v.p2, c.k3 = v.k3;
  c.width = v.width, c.height = v.height;
  c.depth_factor = v.depth_factor;
  c.baseline_m = v.baseline_m;
  c.rolling_shutter_readout_s = v.rolling_shutter_readout_s;
  return c;
}

TrackingState toApi(::plumb::TrackingState state) {
  switch (state) {
    case ::plumb::TrackingState::kOk: return TrackingState::kOk;
    case ::plumb::TrackingState::kWeak: return TrackingState::kWeak;
    case ::plumb::TrackingState::kLost: return TrackingState::kLost;
    case ::plumb::TrackingState::kNotInitialized: break;
  }
  return TrackingState::kNotInitialized;
}

void toTrackOutput(const FrameOutput& f, TrackOutput* out) {
  out->sequence = f.sequence;
  out->timestamp_s = f.timestamp_s;
  out->state = toApi(f.state);
  out->has_pose = f.has_pose;
  out->T_world_cam = f.T_world_cam;
  out->covariance_valid = f.has_pose && f.track.covariance_valid;
  out->covariance = f.track.covariance;
  out->keyframe = f.keyframe;
  out->relocalized = f.relocalized;
  out->new_map = f.new_map;
  out->point_inliers = f.track.point_inliers;
  out->line_inliers = f.track.line_inliers;
}

FinishedPose toFinished(const StampedPose& s) {
  FinishedPose p;
  p.timestamp_s = s.timestamp;
  p.valid = s.valid;
  p.dropped = s.dropped;
  p.T_world_cam = s.T_world_cam;
  return p;
}

FinishedPose toFinished(const FinishedFrame& f) {
  FinishedPose p = toFinished(toStampedPose(f));
  p.sequence = f.sequence;
  return p;
}

StampedPose toStamped(const FinishedPose& p) {
  StampedPose s;
  s.timestamp = p.timestamp_s;
  s.T_world_cam = p.T_world_cam;
  s.valid = p.valid;
  s.dropped = p.dropped;
  return s;
}

Counters toCounters(const OdometryStats& s, uint64_t frames, uint64_t extraction_failures) {
  Counters c;
  c.frames = frames;
  c.frames_ok = s.frames_ok;
  c.frames_weak = s.frames_weak;
  c.frames_lost = s.frames_lost;
  c.keyframes = s.keyframes;
  c.relocalizations = s.relocalizations;
  c.map_segments = s.segments;
  c.extraction_failures = extraction_failures;
  return c;
}

SystemOptions systemOptions(bool lines, int line_samples, int output_delay_frames) {
  SystemOptions options;
  setLineSamples(line_samples, lines, &options.odometry);
  options.output_delay_frames = output_delay_frames;
  return options;
}

}  // namespace plumb::api

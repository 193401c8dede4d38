#pragma once
// What the pipeline's outputs become as stamped covariances (sensor/stamped_covariance.h): one
// conversion for every sink (`plumb run`'s files, the NEES study and tests).
#include "pipeline/odometry/local_mapper.h"
#include "pipeline/odometry/odometry_system.h"
#include "sensor/stamped_covariance.h"

namespace plumb {

inline StampedCovariance toStampedCovariance(const RetiredKeyframe& kf) {
  StampedCovariance c;
  c.timestamp = kf.timestamp_s;
  c.valid = kf.covariance_valid;
  c.covariance = kf.covariance;
  c.has_relative = kf.uncertainty.hasRelative();
  c.previous_timestamp = kf.uncertainty.previous_timestamp_s;
  c.T_previous_this = kf.uncertainty.T_previous_this;
  c.relative_covariance = kf.uncertainty.relative_covariance;
  return c;
}

// For a frame with a pose (FrameOutput::has_pose); `valid` when both covariances are.
inline StampedTrackedCovariance toStampedTrackedCovariance(const FrameOutput& out) {
  StampedTrackedCovariance c;
  c.timestamp = out.timestamp_s;
  c.valid = out.track.covariance_valid && out.track.covariance_local_valid;
  c.T_world_cam = out.T_world_cam;
  c.covariance = out.track.covariance;
  c.covariance_local = out.track.covariance_local;
  c.has_previous = out.track.has_previous;
  c.previous_timestamp = out.track.previous_timestamp_s;
  c.T_world_previous = out.track.T_world_previous;
  return c;
}

}  // namespace plumb

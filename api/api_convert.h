#pragma once
// Conversions between the public API's value types (api/plumb/odometry.h) and plumb's own.
#include "api/plumb/odometry.h"
#include "drivers/trajectory/trajectory_io.h"
#include "pipeline/odometry/odometry_system.h"
#include "platform/status.h"
#include "sensor/camera.h"

namespace plumb::api {

inline Status fromStatus(const ::plumb::Status& status) {
  return status.ok() ? Status::Ok() : Status::Error(status.message());
}
CameraValues toValues(const PinholeCamera& camera);
PinholeCamera toCamera(const CameraValues& values);
TrackingState toApi(::plumb::TrackingState state);
void toTrackOutput(const FrameOutput& frame, TrackOutput* out);
FinishedPose toFinished(const FinishedFrame& frame);
FinishedPose toFinished(const StampedPose& pose);
StampedPose toStamped(const FinishedPose& pose);
Counters toCounters(const OdometryStats& stats, uint64_t frames, uint64_t extraction_failures);
// SystemOptions from the API's options (validated by OdometrySystem::create).
SystemOptions systemOptions(bool lines, int line_samples, int output_delay_frames);

}  // namespace plumb::api

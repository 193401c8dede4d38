#pragma once
// Geometry of map lines built from one observation: the 3D segment endpoints are the points of
// the robustly fitted 3D line closest to the viewing rays of the 2D endpoints (so a map line spans
// what was seen, not just its sample range).
#include <Eigen/Core>

#include "sensor/camera.h"
#include "pipeline/frontend/frame_features.h"

namespace plumb {

// Endpoints in the camera frame. Falls back to the outermost samples when a ray is (nearly)
// parallel to the line or the closest point is behind the camera. Requires line.has_3d and
// line.num_samples >= 2.
void mapLineEndpointsCam(const PinholeCamera& camera, const LineObservation& line, Eigen::Vector3d* start_cam,
                         Eigen::Vector3d* end_cam);

}  // namespace plumb

#include "pipeline/odometry/map_line_geometry.h"

#include <cmath>

namespace plumb {

namespace {

// Point of the line p0 + t*dir (dir unit) closest to the ray s*r from the camera centre.
bool closestOnLineToRay(const Eigen::Vector3d& p0, const Eigen::Vector3d& dir, const Eigen::Vector3d& r,
                        Eigen::Vector3d* out) {
  const double b = dir.dot(r), c = r.dot(r);
  const double d = dir.dot(p0), e = r.dot(p0);
  const double denom = c - b * b;  // |dir| = 1
  if (denom < 1e-6 * c) return false;  // ray (nearly) parallel to the line
  const double t = (b * e - c * d) / denom;
  *out = p0 + t * dir;
  return out->z() > 0.05;
}

}  // namespace

void mapLineEndpointsCam(const PinholeCamera& camera, const LineObservation& line, Eigen::Vector3d* start_cam,
                         Eigen::Vector3d* end_cam) {
  const Eigen::Vector3d p0 = line.line_point_cam.cast<double>();
  const Eigen::Vector3d dir = line.line_dir_cam.cast<double>().normalized();
  const Eigen::Vector3d r_start = camera.unproject(line.start_px.x(), line.start_px.y(), 1.0);
  const Eigen::Vector3d r_end = camera.unproject(line.end_px.x(), line.end_px.y(), 1.0);
  const int last = line.num_samples - 1;
  if (!closestOnLineToRay(p0, dir, r_start, start_cam)) *start_cam = line.sample_P_cam[0].cast<double>();
  if (!closestOnLineToRay(p0, dir, r_end, end_cam)) *end_cam = line.sample_P_cam[last].cast<double>();
}

}  // namespace plumb

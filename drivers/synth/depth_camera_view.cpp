#include "drivers/synth/depth_camera_view.h"

#include <cmath>

#include "drivers/synth/synthetic_scene.h"

namespace plumb {

// A Kinect v1 / RealSense-like depth camera: the same 640x480 image as the colour camera (so its
// images can also be fed to plumb as if registered, for comparison), a longer focal length
// (58 x 46 degrees against the colour camera's 63 x 49: the colour image's border has no depth),
// an off-centre principal point, 2.5 cm to the side of the colour camera with a few millimetres
// of height and depth offset, and turned 0.53 degrees (rotation vector (3, -8, 4) mrad).
DepthCamera synthOffsetDepthCamera() {
  DepthCamera d;
  d.fx = 575.0;
  d.fy = 575.0;
  d.cx = 314.0;
  d.cy = 243.0;
  d.width = 640;
  d.height = 480;
  const Eigen::Vector3d rotation_vector(0.003, -0.008, 0.004);
  const Eigen::Quaterniond q(Eigen::AngleAxisd(rotation_vector.norm(), rotation_vector.normalized()));
  d.qx = q.x();
  d.qy = q.y();
  d.qz = q.z();
  d.qw = q.w();
  d.tx = 0.025;
  d.ty = 0.001;
  d.tz = -0.002;
  return d;
}

DepthCamera synthOffsetDepthCameraQvga() {
  DepthCamera d = synthOffsetDepthCamera();
  // Pixel centres of the half-resolution image: (u + 0.5) / 2 - 0.5.
  d.fx /= 2;
  d.fy /= 2;
  d.cx = (d.cx + 0.5) / 2 - 0.5;
  d.cy = (d.cy + 0.5) / 2 - 0.5;
  d.width /= 2;
  d.height /= 2;
  return d;
}

namespace synth {

Status validateDepthCamera(const SynthOptions& o) {
  if (!o.depth_camera) return Status::Ok();
  if (o.depth_camera->hasDistortion())
    return Status::Error("synth: the depth camera must have no distortion (the renderer is a pinhole camera)");
  PinholeCamera camera = synthCamera();
  camera.depth_camera = o.depth_camera;
  const std::string problem = camera.validate();
  if (!problem.empty()) return Status::Error("synth: depth camera: " + problem);
  return Status::Ok();
}

DepthCameraView::DepthCameraView(const SceneModel& model, const DepthCamera& depth_camera)
    : lens_(depthCameraLens(depth_camera)), T_colour_depth_(depth_camera.T_colour_depth()), renderer_(model, lens_) {}

void DepthCameraView::render(const Eigen::Isometry3d& T_world_colour) {
  renderer_.renderDepth(T_world_colour * T_colour_depth_);
}

}  // namespace synth
}  // namespace plumb

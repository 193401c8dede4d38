#pragma once
// DepthCameraView: the scene seen by a depth camera beside the colour camera, not registered to
// it (SynthOptions::depth_camera), as UVC depth cameras (RealSense, Orbbec, a Kinect v1 without
// registration) deliver depth: its own intrinsics and image size, its own viewpoint
// T_world_depth = T_world_colour * T_colour_depth. Only the z-buffer pass of a second
// FrameRenderer runs (no painting, no shading); colour and ground truth stay the colour camera's.
// The renderer is a pinhole: the depth camera must have no distortion (validate(SynthOptions)).
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "drivers/synth/frame_renderer.h"
#include "drivers/synth/scene_model.h"
#include "platform/status.h"
#include "sensor/camera.h"

namespace plumb {
struct SynthOptions;
}

namespace plumb::synth {

// SynthOptions::depth_camera, when set: no distortion, and plausible beside synthCamera()
// (PinholeCamera::validate). Part of validate(SynthOptions).
Status validateDepthCamera(const SynthOptions& options);

class DepthCameraView {
 public:
  DepthCameraView(const SceneModel& model, const DepthCamera& depth_camera);
  // Renders the depth camera's view for the colour camera at T_world_colour.
  void render(const Eigen::Isometry3d& T_world_colour);
  // z in metres along the depth camera's optical axis (+inf where nothing was hit), CV_32FC1 of
  // the depth camera's size.
  const cv::Mat& depth() const { return renderer_.depth(); }

 private:
  PinholeCamera lens_;  // before renderer_, which keeps a reference to it
  Eigen::Isometry3d T_colour_depth_;
  FrameRenderer renderer_;
};

}  // namespace plumb::synth

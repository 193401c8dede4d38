#pragma once
// Rolling-shutter compensation of a frame's features (Kinect-class RGB-D cameras).
//
// A rolling-shutter sensor exposes its rows one after another: row v is taken
//   dt(v) = (v - cy) / height * readout_s
// after the middle row. While the camera turns at tens of degrees per second, the rows of one
// frame see the scene from slightly different poses (at 90 deg/s and 25 ms readout the top and the
// bottom row differ by > 2 deg, ~20 px). A global-shutter model fitted to such a frame leans its
// rotation and, through the rotation-translation ambiguity of a narrow field of view, its
// translation by centimetres; that is the dominant error on fast rotations (TUM fr1/rpy).
//
// With the camera's velocity xi (a twist per second: T_cam_world(t + dt) = exp(dt xi) T_cam_world(t),
// taken from the constant-velocity model), a point measured in the camera of row v, X_v, is in the
// camera of the middle row X_mid = exp(-dt(v) xi) X_v. Every feature is moved to the middle-row
// camera: keypoints (pixel, depth, u_r, 3D point), line endpoints (and so the line coefficients)
// and line-guidance samples. The whole frame then obeys the global-shutter model the tracker,
// the map and local BA use. Depth is taken to share the colour row's time (registered depth).
#include "sensor/camera.h"
#include "pipeline/frontend/frame_features.h"
#include "solver/types.h"

namespace plumb {

// Moves every feature of `frame` to the middle row's time; rebuilds its keypoint grid.
// Does nothing when readout_s <= 0 (global shutter). The information matrices are kept: the
// correction is a small rigid motion per feature, below the model's resolution.
void compensateRollingShutter(const PinholeCamera& camera, double readout_s, const Vector6d& twist_per_s,
                              FrameFeatures* frame);

}  // namespace plumb

#pragma once
// The pinhole + virtual-stereo intrinsics the solver needs. The solver must not include
// pipeline/, so the front end converts its PinholeCamera into this plain struct.
//
//   u   = fx * X / Z + cx
//   v   = fy * Y / Z + cy
//   u_r = u - bf / Z          (right-image column of a virtual stereo rig, paper section V-D)
//
// fy may be negative (images stored bottom-up); nothing in the solver assumes fy > 0.
namespace plumb {

struct CameraIntrinsics {
  double fx = 0.0;
  double fy = 0.0;
  double cx = 0.0;
  double cy = 0.0;
  double bf = 0.0;  // fx * baseline [pixel * m]; ORB-SLAM2's TUM setting is fx * 0.08 m
};

}  // namespace plumb

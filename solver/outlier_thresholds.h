#pragma once
// Chi-square thresholds (95 %) that classify an observation as an outlier after an optimisation,
// by the degrees of freedom of its error. One definition for tracking (pose_optimizer.h), local BA
// (local_ba.h) and the odometry options that configure them (pipeline/odometry/odometry_options.h).

namespace plumb {

struct OutlierChi2 {
  double stereo = 7.815;  // RGB-D point [u, v, u_r]: 3 dof
  double mono = 5.991;    // point without depth [u, v]: 2 dof
  double line = 3.841;    // line-guidance sample, signed distance to the 2D line: 1 dof
};

}  // namespace plumb

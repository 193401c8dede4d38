#pragma once
// Camera file: one `key value` per line, `#` starts a comment. Keys:
//   fx fy cx cy            intrinsics in pixels (required; fy may be negative, never zero)
//   k1 k2 p1 p2 k3         Brown-Conrady distortion, OpenCV order (optional, default 0)
//   width height           image size in pixels (optional, default 640 480)
//   depth_factor           raw depth units per metre (optional, default 5000)
//   baseline               virtual stereo baseline in metres (optional, default 0.08)
//   rolling_shutter_readout  seconds from first to last row (optional, default 0)
//   depth_fx depth_fy depth_cx depth_cy depth_k1..depth_k3 depth_width depth_height
//   depth_to_colour_qx qy qz qw tx ty tz
//                          optional: depth from a separate depth camera, not registered to colour
//                          (all but the distortion required once one is given; sensor/depth_camera.h)
// Unknown keys, repeated keys, unparsable or non-finite values are errors naming file and line.
// Format documented in docs/DATA_FORMATS.md.
#include <string>

#include "sensor/camera.h"
#include "platform/status.h"

namespace plumb {

Status readCameraFile(const std::string& path, PinholeCamera* out);

// Writes every key with full precision (%.17g), so read(write(c)) == c bit for bit.
Status writeCameraFile(const std::string& path, const PinholeCamera& camera);

}  // namespace plumb

#pragma once
// DepthRegistration: a depth image from a separate depth camera (PinholeCamera::depth_camera,
// sensor/depth_camera.h) re-expressed in the colour camera, so that every later step reads depth
// at a colour pixel as if the sensor had registered it.
//
// Forward warping with a z-buffer. Each depth pixel with a reading is back-projected through the
// depth lens (its undistorted ray, precomputed), moved by T_colour_depth, projected through the
// colour lens (pinhole + the colour camera's distortion: depth is registered to the distorted
// colour image, as the extractor expects) and written as the colour camera's z:
//   - footprint splat: the pixel covers the colour pixels whose centres fall inside its footprint,
//     the bounding box of its four corners projected at unit depth (precomputed; scaled by
//     1 - t_z / z per frame, exact when t_z = 0), grown by 0.25 px per side. Footprints of one
//     surface tile the colour image, so a lower-resolution depth camera leaves no cracks, and the
//     growth closes the sub-pixel gaps that the baseline's parallax opens between neighbours of
//     different depth on slanted surfaces;
//   - z-buffer: where several depth pixels land on one colour pixel (the far side of an edge seen
//     by the depth camera but hidden from the colour camera), the nearest wins;
//   - holes: colour pixels that no depth pixel reaches read 0 (no reading): the depth camera's
//     occlusion shadow beside foreground edges, and the parts of the colour view it does not see.
//     They are not filled in: the extractor already treats 0 as "no depth".
// The output is in the input's raw units (depth factor unchanged); a colour z beyond 65535 units
// reads 0, never a clamped value.
//
// Allocation: the tables (one ray and one footprint per depth pixel) and a row of scratch are
// built in the constructor; registerInto() allocates nothing once `out` has the colour size
// (tested). Speed: each depth row is projected in one branch-free pass the compiler vectorises
// (SoA tables), then splatted. Not thread-safe (the row scratch): one object per thread.
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "sensor/camera.h"

namespace plumb {

class DepthRegistration {
 public:
  // `camera` is the colour camera; registration is active when camera.depth_camera is set.
  explicit DepthRegistration(const PinholeCamera& camera);

  bool active() const { return active_; }
  int depthWidth() const { return depth_width_; }
  int depthHeight() const { return depth_height_; }

  // depth: CV_16UC1 of the depth camera's size, raw units (depth_factor units per metre).
  // out: CV_16UC1 of the colour camera's size ((re)allocated only when it is not). Returns false
  // (out untouched) when registration is inactive or depth has another size or type.
  bool registerInto(const cv::Mat& depth, double depth_factor, cv::Mat& out);

 private:
  template <bool kColourDistortion>
  void projectRow(int v, const uint16_t* depth_row, float to_metres, float to_raw);
  void splatRow(cv::Mat& out);

  PinholeCamera colour_;
  bool active_ = false;
  int depth_width_ = 0, depth_height_ = 0;
  float tx_ = 0, ty_ = 0, tz_ = 0;
  float ceil_offset_ = 0;  // > every clamped bound, for ceil by truncation
  // Per depth pixel, row-major: R_colour_depth * undistorted ray (x_n, y_n, 1) of its centre, and
  // half its footprint in colour pixels at unit depth (translation ignored, growth included).
  std::vector<float> ray_x_, ray_y_, ray_z_, half_w_, half_h_;
  // One depth row's footprints ([x0, x1) x [y0, y1) colour pixels, empty when x0 >= x1) and values.
  std::vector<int32_t> x0_, x1_, y0_, y1_, raw_;
};

}  // namespace plumb

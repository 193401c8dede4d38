#pragma once
// FrameRenderer: noise-free colour and depth of a SceneModel seen from one camera pose.
//
// Two passes over preallocated buffers (no allocation per frame):
//  1. Rasterise every front-facing quad into a z-buffer of (depth, quad id). Each quad is clipped
//     to the near plane, projected, and filled span by span; depth at a pixel centre is the exact
//     ray-plane intersection z = d / (n . r), so depth is exact up to float rounding (no
//     interpolation error, which the reprojection test relies on).
//  2. Shade: a bilinear lookup in the face's texture, lighting baked in (light_baking.h), painted
//     when a frame first shows the face (baked_textures.h: only quads that won a pixel in pass 1
//     are ever sampled, so the first frame paints only what it sees). Pixels whose
//     4-neighbours carry another quad id lie on a silhouette or crease: they are supersampled
//     3x3 by ray casting against the quads of their 3x3 neighbourhood, so edges are anti-aliased
//     and the line detector sees clean straight segments. Depth stays the centre sample (a real
//     sensor does not blend depths either).
// Shading is view-independent (Lambert), so a surface point has the same colour in every frame.
// Every quad must have a texture recipe (planLightMaps gives flat faces a light map).
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "drivers/synth/baked_textures.h"
#include "drivers/synth/scene_model.h"
#include "platform/huge_page_buffer.h"
#include "sensor/camera.h"

namespace plumb::synth {

class FrameRenderer {
 public:
  // Keeps references to model and camera (both must outlive the renderer); allocates all buffers
  // but the textures, which are painted as frames first show their faces.
  FrameRenderer(const SceneModel& model, const PinholeCamera& camera);
  // Not movable: the helper thread's first job (populateBuffers) holds `this`.
  FrameRenderer(const FrameRenderer&) = delete;
  FrameRenderer& operator=(const FrameRenderer&) = delete;

  void render(const Eigen::Isometry3d& T_world_cam);
  // The z-buffer pass alone (no painting, no shading): depth() is valid after it, colour() is
  // not. For a second camera that sees only depth (depth_camera_view.h).
  void renderDepth(const Eigen::Isometry3d& T_world_cam);

  // Results of the last render: linear colour (BGR, 0..255, may exceed 255 slightly before
  // quantisation) and depth z in metres along the optical axis (+inf where nothing was hit).
  const cv::Mat& colour() const { return colour_bgr_; }  // CV_32FC3
  const cv::Mat& depth() const { return depth_m_; }       // CV_32FC1
  int edgePixelCount() const { return edge_pixels_; }     // pixels supersampled in the last render
  // Whether the last render painted faces (and so used the helper thread).
  bool paintedFaces() const { return painted_faces_; }
  // The renderer's second thread, for the caller's own two-part work on the same thread (the
  // scene quantises colour and depth on it); not while render() runs.
  runtime::HelperThread& helper() { return *helper_; }

 private:
  // A quad moved into the camera frame for the current pose.
  struct QuadInCamera {
    Eigen::Vector3d origin, axis_u, axis_v, normal;
    double plane_offset = 0;  // plane: normal . X = plane_offset (< 0 when facing the camera)
    bool facing = false;
  };

  // Helper-thread job started by the constructor: maps buffers_ and the painting scratch.
  static void populateBuffers(void* renderer);
  void transformQuads(const Eigen::Isometry3d& T_world_cam);
  // Transform + rasterise every facing quad; fills won_quads_.
  void rasterise(const Eigen::Isometry3d& T_world_cam);
  // Returns whether the quad won at least one pixel (so far: a later quad may cover it again).
  bool rasteriseQuad(int quad_index);
  void shadePixels(bool two_threads);
  // Rows [row_begin, row_end) of shadePixels(); returns the pixels supersampled.
  int shadeRows(int row_begin, int row_end);
  // Nearest quad among `candidates` hit by the ray through (u, v); -1 if none. Sets *z.
  int castRay(double u, double v, const int* candidates, int count, double* z) const;
  cv::Vec3f shadePoint(int quad_index, const Eigen::Vector3d& P_cam) const;
  cv::Vec3f sampleTexture(const SurfaceTexture& texture, double s_m, double t_m) const;

  const SceneModel& model_;
  const PinholeCamera& camera_;
  HugePageBuffer buffers_;  // colour, depth and quad ids (before textures_, which borrows colour)
  BakedTextures textures_;
  std::vector<QuadInCamera> quads_cam_;
  std::vector<int> won_quads_;         // quads that won a pixel in the last rasterisation
  std::vector<double> ray_x_, ray_y_;  // (u - cx) / fx per column, (v - cy) / fy per row
  int32_t* quad_id_ = nullptr;         // per pixel, -1 = nothing
  cv::Mat colour_bgr_, depth_m_;
  std::vector<int32_t> fallback_quad_id_;  // quad_id_'s memory if buffers_ could not be had
  int edge_pixels_ = 0;
  bool painted_faces_ = false;
  // Paints the next face while lighting the last, and shades half the rows (runtime/helper_thread.h).
  // Last member: destroyed first, so it finishes any job before the buffers go.
  std::unique_ptr<runtime::HelperThread> helper_ = std::make_unique<runtime::HelperThread>();
};

}  // namespace plumb::synth

// Z-buffer rasteriser and shader of the synthetic room (see frame_renderer.h).
#include "drivers/synth/frame_renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "platform/memory_residency.h"

namespace plumb::synth {
namespace {

constexpr double kNearPlaneM = 0.05;
// Pixel centres within this of a polygon edge count as inside, so quads sharing an edge leave no
// crack between them (the z-test settles the overlap).
constexpr double kSpanSlackPx = 1e-3;
// Quads whose plane is seen this edge-on (|n . r| tiny) are skipped at that pixel.
constexpr double kMinDenominator = 1e-9;

// Sub-pixel offsets of the 3x3 supersampling grid.
constexpr double kSubOffsets[3] = {-1.0 / 3.0, 0.0, 1.0 / 3.0};

// Clips a convex polygon to z >= kNearPlaneM (Sutherland-Hodgman). Returns the vertex count.
int clipToNearPlane(const Eigen::Vector3d* in, int count, Eigen::Vector3d* out) {
  int n = 0;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d& a = in[i];
    const Eigen::Vector3d& b = in[(i + 1) % count];
    const bool a_in = a.z() >= kNearPlaneM, b_in = b.z() >= kNearPlaneM;
    if (a_in) out[n++] = a;
    if (a_in != b_in) out[n++] = a + (b - a) * ((kNearPlaneM - a.z()) / (b.z() - a.z()));
  }
  return n;
}

size_t pixelsOf(const PinholeCamera& camera) { return static_cast<size_t>(camera.width) * camera.height; }

}  // namespace

// Colour, depth and quad ids in one huge-page block (few page faults on the first frame). The
// colour part doubles as the painting canvas: faces are painted after rasterising and before
// shading (render()), when the colour buffer holds nothing live.
FrameRenderer::FrameRenderer(const SceneModel& model, const PinholeCamera& camera)
    : model_(model),
      camera_(camera),
      buffers_(pixelsOf(camera) * (sizeof(cv::Vec3f) + sizeof(float) + sizeof(int32_t))),
      textures_(model, buffers_.data(), buffers_.data() ? pixelsOf(camera) * sizeof(cv::Vec3f) : 0) {
  quads_cam_.resize(model.quads.size());
  won_quads_.reserve(model.quads.size());
  ray_x_.resize(camera.width);
  ray_y_.resize(camera.height);
  for (int x = 0; x < camera.width; ++x) ray_x_[x] = (x - camera.cx) / camera.fx;
  for (int y = 0; y < camera.height; ++y) ray_y_[y] = (y - camera.cy) / camera.fy;
  const size_t pixels = pixelsOf(camera);
  // The render buffers and the painting scratch are written by every first frame. The helper
  // thread maps them now (the kernel only, no byte touched), while the caller goes on to build
  // whatever reads the frames; render() waits for it before its first use of the helper.
  helper_->startJob(&populateBuffers, this);
  if (buffers_.data()) {
    colour_bgr_ = cv::Mat(camera.height, camera.width, CV_32FC3, buffers_.data());
    depth_m_ = cv::Mat(camera.height, camera.width, CV_32FC1, buffers_.data() + pixels * sizeof(cv::Vec3f));
    quad_id_ = reinterpret_cast<int32_t*>(buffers_.data() + pixels * (sizeof(cv::Vec3f) + sizeof(float)));
  } else {
    colour_bgr_.create(camera.height, camera.width, CV_32FC3);
    depth_m_.create(camera.height, camera.width, CV_32FC1);
    fallback_quad_id_.resize(pixels);
    quad_id_ = fallback_quad_id_.data();
  }
}

void FrameRenderer::populateBuffers(void* renderer) {
  FrameRenderer& r = *static_cast<FrameRenderer*>(renderer);
  (void)populateForWrite(r.buffers_.data(), r.buffers_.size());
  (void)populateForWrite(r.textures_.scratchData(), r.textures_.scratchBytes());
}

void FrameRenderer::render(const Eigen::Isometry3d& T_world_cam) {
  rasterise(T_world_cam);
  // Painting draws in the colour buffer (borrowed canvas, see the constructor): all of it before
  // shading writes colours. A face's texels do not depend on when it is painted.
  // The helper thread works only on frames that paint faces (the first frame, and first sightings
  // later): a steady run's frames render on the caller alone, as they did before it existed, so
  // a real-time pipeline fed by this scene keeps the other core.
  painted_faces_ = textures_.prepareAll(won_quads_.data(), static_cast<int>(won_quads_.size()), helper_.get()) > 0;
  shadePixels(painted_faces_);
}

void FrameRenderer::renderDepth(const Eigen::Isometry3d& T_world_cam) {
  rasterise(T_world_cam);
  painted_faces_ = false;
}

void FrameRenderer::rasterise(const Eigen::Isometry3d& T_world_cam) {
  transformQuads(T_world_cam);
  // Plain fill: cv::Mat::setTo allocates a scratch buffer on every call.
  float* depth = depth_m_.ptr<float>();
  std::fill(depth, depth + depth_m_.total(), std::numeric_limits<float>::infinity());
  std::fill(quad_id_, quad_id_ + depth_m_.total(), -1);
  // Shading samples only quads whose id is in the z-buffer (pixel centres, and the 3x3
  // neighbourhoods supersampled at edges), all of which won a pixel while rasterising.
  won_quads_.clear();
  for (int q = 0; q < static_cast<int>(quads_cam_.size()); ++q)
    if (quads_cam_[q].facing && rasteriseQuad(q)) won_quads_.push_back(q);
}

void FrameRenderer::transformQuads(const Eigen::Isometry3d& T_world_cam) {
  const Eigen::Isometry3d T_cam_world = T_world_cam.inverse();
  const Eigen::Matrix3d& R_cam_world = T_cam_world.linear();
  for (size_t q = 0; q < quads_cam_.size(); ++q) {
    const SceneQuad& quad = model_.quads[q];
    QuadInCamera& qc = quads_cam_[q];
    qc.origin = T_cam_world * quad.origin_world;
    qc.axis_u = R_cam_world * quad.axis_u_world;
    qc.axis_v = R_cam_world * quad.axis_v_world;
    qc.normal = R_cam_world * quad.normal_world;
    qc.plane_offset = qc.normal.dot(qc.origin);
    qc.facing = qc.plane_offset < 0;  // the camera (origin) is on the front side
  }
}

bool FrameRenderer::rasteriseQuad(int quad_index) {
  const SceneQuad& quad = model_.quads[quad_index];
  const QuadInCamera& qc = quads_cam_[quad_index];
  const Eigen::Vector3d corners[4] = {qc.origin, qc.origin + qc.axis_u * quad.length_u,
                                      qc.origin + qc.axis_u * quad.length_u + qc.axis_v * quad.length_v,
                                      qc.origin + qc.axis_v * quad.length_v};
  Eigen::Vector3d clipped[8];
  const int count = clipToNearPlane(corners, 4, clipped);
  if (count < 3) return false;
  bool won_a_pixel = false;
  double px[8], py[8];
  double y_min = std::numeric_limits<double>::infinity(), y_max = -y_min;
  for (int i = 0; i < count; ++i) {
    px[i] = camera_.fx * clipped[i].x() / clipped[i].z() + camera_.cx;
    py[i] = camera_.fy * clipped[i].y() / clipped[i].z() + camera_.cy;
    y_min = std::min(y_min, py[i]);
    y_max = std::max(y_max, py[i]);
  }
  const int row_begin = std::max(0, static_cast<int>(std::ceil(y_min - kSpanSlackPx)));
  const int row_end = std::min(camera_.height - 1, static_cast<int>(std::floor(y_max + kSpanSlackPx)));
  const int width = camera_.width;
  for (int y = row_begin; y <= row_end; ++y) {
    // Span of the convex polygon on this row: extreme crossings of its edges.
    double x_left = std::numeric_limits<double>::infinity(), x_right = -x_left;
    for (int i = 0; i < count; ++i) {
      const int j = (i + 1) % count;
      const double ya = py[i], yb = py[j];
      if (std::min(ya, yb) - kSpanSlackPx > y || std::max(ya, yb) + kSpanSlackPx < y) continue;
      if (std::abs(yb - ya) < 1e-12) {
        x_left = std::min({x_left, px[i], px[j]});
        x_right = std::max({x_right, px[i], px[j]});
        continue;
      }
      const double s = std::clamp((y - ya) / (yb - ya), 0.0, 1.0);
      const double x = px[i] + s * (px[j] - px[i]);
      x_left = std::min(x_left, x);
      x_right = std::max(x_right, x);
    }
    const int col_begin = std::max(0, static_cast<int>(std::ceil(x_left - kSpanSlackPx)));
    const int col_end = std::min(width - 1, static_cast<int>(std::floor(x_right + kSpanSlackPx)));
    if (col_begin > col_end) continue;
    float* depth_row = depth_m_.ptr<float>(y);
    int32_t* id_row = quad_id_ + static_cast<size_t>(y) * width;
    const double row_term = qc.normal.y() * ray_y_[y] + qc.normal.z();
    for (int x = col_begin; x <= col_end; ++x) {
      const double denominator = qc.normal.x() * ray_x_[x] + row_term;  // n . r, r = (rx, ry, 1)
      if (denominator > -kMinDenominator) continue;
      const double z = qc.plane_offset / denominator;
      if (z < depth_row[x]) {
        depth_row[x] = static_cast<float>(z);
        id_row[x] = quad_index;
        won_a_pixel = true;
      }
    }
  }
  return won_a_pixel;
}

int FrameRenderer::castRay(double u, double v, const int* candidates, int count, double* z) const {
  const Eigen::Vector3d ray((u - camera_.cx) / camera_.fx, (v - camera_.cy) / camera_.fy, 1.0);
  int best = -1;
  double best_z = std::numeric_limits<double>::infinity();
  for (int i = 0; i < count; ++i) {
    const int q = candidates[i];
    const QuadInCamera& qc = quads_cam_[q];
    const double denominator = qc.normal.dot(ray);
    if (denominator > -kMinDenominator) continue;
    const double hit_z = qc.plane_offset / denominator;
    if (hit_z < kNearPlaneM || hit_z >= best_z) continue;
    const Eigen::Vector3d offset = ray * hit_z - qc.origin;
    const double s = offset.dot(qc.axis_u), t = offset.dot(qc.axis_v);
    const SceneQuad& quad = model_.quads[q];
    if (s < -1e-9 || t < -1e-9 || s > quad.length_u + 1e-9 || t > quad.length_v + 1e-9) continue;
    best = q;
    best_z = hit_z;
  }
  *z = best_z;
  return best;
}

inline cv::Vec3f FrameRenderer::sampleTexture(const SurfaceTexture& texture, double s_m, double t_m) const {
  const cv::Mat& bgr = texture.bgr;
  const float x = std::clamp(static_cast<float>(s_m * texture.texels_per_metre) - 0.5f, 0.0f, bgr.cols - 1.001f);
  const float y = std::clamp(static_cast<float>(t_m * texture.texels_per_metre) - 0.5f, 0.0f, bgr.rows - 1.001f);
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const float ax = x - x0, ay = y - y0;
  const uchar* p00 = bgr.ptr<uchar>(y0) + 3 * x0;
  const uchar* p10 = p00 + bgr.step[0];
  const float w00 = (1 - ax) * (1 - ay), w01 = ax * (1 - ay), w10 = (1 - ax) * ay, w11 = ax * ay;
  return cv::Vec3f(w00 * p00[0] + w01 * p00[3] + w10 * p10[0] + w11 * p10[3],
                   w00 * p00[1] + w01 * p00[4] + w10 * p10[1] + w11 * p10[4],
                   w00 * p00[2] + w01 * p00[5] + w10 * p10[2] + w11 * p10[5]);
}

inline cv::Vec3f FrameRenderer::shadePoint(int quad_index, const Eigen::Vector3d& P_cam) const {
  // Lighting is baked into the texture (light_baking.h): shading is one bilinear lookup.
  const QuadInCamera& qc = quads_cam_[quad_index];
  const Eigen::Vector3d offset = P_cam - qc.origin;
  return sampleTexture(textures_.texture(quad_index), offset.dot(qc.axis_u), offset.dot(qc.axis_v));
}

void FrameRenderer::shadePixels(bool two_threads) {
  if (!two_threads) {
    edge_pixels_ = shadeRows(0, camera_.height);
    return;
  }
  // Every pixel reads only the z-buffer, the quads and the textures, and writes its own colour.
  // Bands of rows alternate between this thread and the helper (halves would not balance: the
  // floor in the lower half is costlier to sample than the walls above).
  constexpr int kBandRows = 16;
  auto shadeBands = [this](int first_band) {
    int edges = 0;
    for (int y = first_band * kBandRows; y < camera_.height; y += 2 * kBandRows)
      edges += shadeRows(y, std::min(y + kBandRows, camera_.height));
    return edges;
  };
  int here = 0, there = 0;
  helper_->runBoth([&] { here = shadeBands(0); }, [&] { there = shadeBands(1); });
  edge_pixels_ = here + there;
}

int FrameRenderer::shadeRows(int row_begin, int row_end) {
  const int width = camera_.width, height = camera_.height;
  int edge_pixels = 0;
  for (int y = row_begin; y < row_end; ++y) {
    const float* depth_row = depth_m_.ptr<float>(y);
    const int32_t* id_row = quad_id_ + static_cast<size_t>(y) * width;
    cv::Vec3f* colour_row = colour_bgr_.ptr<cv::Vec3f>(y);
    for (int x = 0; x < width; ++x) {
      const int id = id_row[x];
      if (id < 0) {
        colour_row[x] = cv::Vec3f(0, 0, 0);
        continue;
      }
      const double z = depth_row[x];
      const Eigen::Vector3d P_cam(ray_x_[x] * z, ray_y_[y] * z, z);
      const cv::Vec3f centre = shadePoint(id, P_cam);
      const bool edge = (x > 0 && id_row[x - 1] != id) || (x + 1 < width && id_row[x + 1] != id) ||
                        (y > 0 && id_row[x - width] != id) || (y + 1 < height && id_row[x + width] != id);
      if (!edge) {
        colour_row[x] = centre;
        continue;
      }
      ++edge_pixels;
      // Candidate quads: the distinct ids of the 3x3 neighbourhood.
      int candidates[9], count = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        if (y + dy < 0 || y + dy >= height) continue;
        for (int dx = -1; dx <= 1; ++dx) {
          if (x + dx < 0 || x + dx >= width) continue;
          const int c = id_row[dy * width + x + dx];
          if (c >= 0 && std::find(candidates, candidates + count, c) == candidates + count) candidates[count++] = c;
        }
      }
      cv::Vec3f sum(0, 0, 0);
      for (double oy : kSubOffsets) {
        for (double ox : kSubOffsets) {
          double hit_z = 0;
          const int hit = castRay(x + ox, y + oy, candidates, count, &hit_z);
          if (hit < 0) {
            sum += centre;  // a sub-pixel gap between candidates: keep the centre's colour
            continue;
          }
          const Eigen::Vector3d P_hit(((x + ox) - camera_.cx) / camera_.fx * hit_z,
                                      ((y + oy) - camera_.cy) / camera_.fy * hit_z, hit_z);
          sum += shadePoint(hit, P_hit);
        }
      }
      colour_row[x] = sum * (1.0f / 9.0f);
    }
  }
  return edge_pixels;
}

}  // namespace plumb::synth

#include "pipeline/frontend/feature_extractor.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>

#include "pipeline/frontend/depth_sampler.h"
#include "pipeline/frontend/line_extractor.h"
#include "pipeline/frontend/orb_extractor.h"
#include "platform/stage_timing.h"

namespace plumb {
namespace {

// Undistorted-pixel bounds of the whole raw image (barrel distortion pushes them outside
// [0,w)x[0,h)), found by undistorting points along the border.
void undistortedBounds(const PinholeCamera& camera, float* u0, float* v0, float* u1, float* v1) {
  *u0 = *v0 = 1e9f;
  *u1 = *v1 = -1e9f;
  auto add = [&](double u, double v) {
    const Eigen::Vector2d p = camera.undistortPoint(u, v);
    *u0 = std::min(*u0, static_cast<float>(p.x()));
    *v0 = std::min(*v0, static_cast<float>(p.y()));
    *u1 = std::max(*u1, static_cast<float>(p.x()));
    *v1 = std::max(*v1, static_cast<float>(p.y()));
  };
  for (int i = 0; i <= 64; ++i) {
    const double u = (camera.width - 1) * i / 64.0, v = (camera.height - 1) * i / 64.0;
    add(u, 0);
    add(u, camera.height - 1);
    add(0, v);
    add(camera.width - 1, v);
  }
  *u1 += 1;
  *v1 += 1;
}

}  // namespace

FeatureExtractor::FeatureExtractor(const PinholeCamera& camera, const ExtractorOptions& options)
    : camera_(camera), options_(options),
      orb_(new OrbExtractor(camera, options)),
      lines_(new LineExtractor(camera, options)),
      depth_(new DepthSampler(camera, options)) {
  undistortedBounds(camera_, &grid_u0_, &grid_v0_, &grid_u1_, &grid_v1_);
}

FeatureExtractor::~FeatureExtractor() = default;

bool FeatureExtractor::extract(const cv::Mat& bgr, const cv::Mat& depth_raw, double depth_factor, FrameFeatures& out) {
  const auto t_start = StageClock::now();
  const double cpu_start = threadCpuMs();
  out.clear();
  timings_ = ExtractorTimings();
  if (bgr.empty() || bgr.cols != camera_.width || bgr.rows != camera_.height ||
      (bgr.type() != CV_8UC3 && bgr.type() != CV_8UC1)) {
    return false;
  }
  // Grey straight into the pyramid's level 0 (same size and type: cvtColor and copyTo write in
  // place), so the pyramid does not copy it again.
  cv::Mat& grey = orb_->greyInput();
  const uint8_t* const grey_data = grey.data;
  if (bgr.type() == CV_8UC3) {
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  } else {
    bgr.copyTo(grey);
  }
  CV_Assert(grey.data == grey_data);  // written in place, not reallocated

  const auto t_orb = StageClock::now();
  const double cpu_orb = threadCpuMs();
  orb_->extract(grey, out);
  timings_.orb_ms = msSince(t_orb);
  timings_.orb_cpu_ms = threadCpuMs() - cpu_orb;
  timings_.pyramid_ms = orb_->lastPyramidMs();

  const auto t_lines = StageClock::now();
  const double cpu_lines = threadCpuMs();
  lines_->extract(orb_->pyramid(), out);
  timings_.lines_ms = msSince(t_lines);
  timings_.lines_cpu_ms = threadCpuMs() - cpu_lines;
  timings_.lsd_raw_segments = lines_->lastRawSegments();

  const auto t_depth = StageClock::now();
  const double cpu_depth = threadCpuMs();
  const bool depth_ok = !depth_raw.empty() && depth_raw.type() == CV_16UC1 &&
                        depth_raw.cols == camera_.width && depth_raw.rows == camera_.height;
  depth_->attachDepth(depth_ok ? depth_raw : cv::Mat(), depth_factor, out);
  timings_.depth_ms = msSince(t_depth);
  timings_.depth_cpu_ms = threadCpuMs() - cpu_depth;

  out.keypoint_grid.setBounds(grid_u0_, grid_v0_, grid_u1_, grid_v1_);
  out.keypoint_grid.build(static_cast<int>(out.keypoints.size()),
                          [&out](int i) { return out.keypoints[i].px_undist; });

  timings_.total_ms = msSince(t_start);
  timings_.total_cpu_ms = threadCpuMs() - cpu_start;
  timings_.num_keypoints = static_cast<int>(out.keypoints.size());
  timings_.num_lines = static_cast<int>(out.lines.size());
  for (const KeypointObservation& kp : out.keypoints) timings_.num_keypoints_with_depth += kp.depth_m > 0;
  for (const LineObservation& line : out.lines) timings_.num_lines_3d += line.has_3d;
  return true;
}

}  // namespace plumb

#include "pipeline/frontend/line_extractor.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "pipeline/frontend/image_pyramid.h"

namespace plumb {
namespace {

constexpr size_t kSegmentReserve = 8192;

// Size of the pyramid level lines are detected on, computed as ImagePyramid does (+1 for safety):
// the detector's per-pixel buffers need that level, not the full image (at the default level 4,
// 1/4.3 of the pixels: ~6.5 MB less resident memory for a 640x480 camera, same output).
cv::Size lineLevelSize(const PinholeCamera& camera, const ExtractorOptions& options) {
  const int levels = std::clamp(options.num_levels, 1, kPyramidLevels);
  const int level = std::clamp(options.line_level, 0, levels - 1);
  const float scale = std::pow(options.scale_factor, static_cast<float>(level));
  return cv::Size(static_cast<int>(std::lround(camera.width / scale)) + 1,
                  static_cast<int>(std::lround(camera.height / scale)) + 1);
}

}  // namespace

void setLineGeometry(const Eigen::Vector2f& start_px, const Eigen::Vector2f& end_px, LineObservation& line) {
  line.start_px = start_px;
  line.end_px = end_px;
  const Eigen::Vector3d a(start_px.x(), start_px.y(), 1.0), b(end_px.x(), end_px.y(), 1.0);
  const Eigen::Vector3d l0 = a.cross(b);
  const double norm = std::hypot(l0.x(), l0.y());
  line.l = norm > 0 ? Eigen::Vector3d(l0 / norm) : Eigen::Vector3d::Zero();
  const Eigen::Vector2f d = end_px - start_px;
  line.length_px = d.norm();
  line.angle_rad = std::atan2(d.y(), d.x());
}

LineExtractor::LineExtractor(const PinholeCamera& camera, const ExtractorOptions& options)
    : camera_(camera),
      options_(options),
      detector_(std::min(camera.width, lineLevelSize(camera, options).width),
                std::min(camera.height, lineLevelSize(camera, options).height)) {
  // No refinement and scale 1: we hand LSD an already downsampled pyramid level. The other
  // parameters are LSD's published defaults (sigma 0.6, quantisation 2, 22.5 deg, density 0.7).
  if (options.use_opencv_lsd) {
    lsd_ = cv::createLineSegmentDetector(cv::LSD_REFINE_NONE, 1.0, 0.6, 2.0, 22.5, 0.0, 0.7, 1024);
  }
  detected_.resize(kSegmentReserve);
  segments_.reserve(kSegmentReserve);
  ranked_.reserve(kSegmentReserve);
}

void LineExtractor::extract(const ImagePyramid& pyramid, FrameFeatures& out) {
  last_raw_segments_ = 0;
  if (options_.max_lines <= 0) return;  // points only: LSD is not even run
  const int level = std::clamp(options_.line_level, 0, pyramid.numLevels() - 1);
  const cv::Mat& image = pyramid.level(level);
  const float scale = pyramid.scale(level);
  if (lsd_) {
    lsd_->detect(image, segments_);
  } else {
    // Our detector applies the length filter itself (in level pixels).
    const int n = detector_.detect(image, 0.9f * options_.min_line_length_px / scale, detected_.data(),
                                   static_cast<int>(detected_.size()));
    segments_.clear();
    for (int i = 0; i < n; ++i) segments_.emplace_back(detected_[i].x0, detected_[i].y0, detected_[i].x1, detected_[i].y1);
  }
  last_raw_segments_ = static_cast<int>(segments_.size());

  // Pixel centres: level pixel x covers level-0 [x*s, (x+1)*s), centre (x + 0.5) * s - 0.5.
  auto toLevel0 = [scale](float x) { return (x + 0.5f) * scale - 0.5f; };
  ranked_.clear();
  const float min_length = options_.min_line_length_px;
  for (int i = 0; i < static_cast<int>(segments_.size()) && ranked_.size() < ranked_.capacity(); ++i) {
    const cv::Vec4f& s = segments_[i];
    const float length = std::hypot(s[2] - s[0], s[3] - s[1]) * scale;
    if (length >= min_length) ranked_.emplace_back(length, i);
  }
  const int keep = std::min<int>({options_.max_lines, static_cast<int>(ranked_.size()),
                                  static_cast<int>(kMaxLines - out.lines.size())});
  std::partial_sort(ranked_.begin(), ranked_.begin() + keep, ranked_.end(),
                    [](const std::pair<float, int>& a, const std::pair<float, int>& b) {
                      return a.first != b.first ? a.first > b.first : a.second < b.second;
                    });
  for (int k = 0; k < keep; ++k) {
    const cv::Vec4f& s = segments_[ranked_[k].second];
    LineObservation* line = out.lines.emplace_back();
    Descriptor256* descriptor = out.line_descriptors.emplace_back();
    if (line == nullptr || descriptor == nullptr) break;  // cannot happen: keep is bounded above
    const Eigen::Vector2f start = camera_.undistortPoint(toLevel0(s[0]), toLevel0(s[1])).cast<float>();
    const Eigen::Vector2f end = camera_.undistortPoint(toLevel0(s[2]), toLevel0(s[3])).cast<float>();
    setLineGeometry(start, end, *line);
    line->octave = static_cast<int8_t>(level);
    line->response = ranked_[k].first;
    computeLineDescriptor(image, cv::Point2f(s[0], s[1]), cv::Point2f(s[2], s[3]), descriptor_options_,
                          *descriptor);
  }
}

}  // namespace plumb

#include "drivers/trajectory/trajectory_plot.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "drivers/image/png_encoder.h"

namespace plumb {
namespace {

const cv::Scalar kBlack(0, 0, 0), kGrey(200, 200, 200), kWhite(255, 255, 255);
const cv::Scalar kGroundTruthColour(60, 60, 60), kEstimateColour(40, 40, 220);  // BGR
const std::array<cv::Scalar, 3> kAxisColours = {cv::Scalar(40, 40, 220), cv::Scalar(40, 160, 40),
                                                cv::Scalar(220, 90, 30)};  // x red, y green, z blue
const char* const kAxisNames[3] = {"x", "y", "z"};

struct Range {
  double lo = 0, hi = 1;
  void include(double v) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  double span() const { return hi - lo; }
};

// A rectangle of the image with linear data -> pixel maps (y grows upwards on screen).
struct Panel {
  cv::Rect area;
  Range x, y;
  cv::Point toPixel(double data_x, double data_y) const {
    const double u = (data_x - x.lo) / x.span(), v = (data_y - y.lo) / y.span();
    return {area.x + static_cast<int>(std::lround(u * area.width)),
            area.y + area.height - static_cast<int>(std::lround(v * area.height))};
  }
};

// 1, 2 or 5 times a power of ten, giving about `target` ticks over `span`.
double niceStep(double span, int target) {
  const double raw = span / target;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0})
    if (m * power >= raw) return m * power;
  return 10 * power;
}

Range padded(Range r, double fraction) {
  if (r.span() <= 1e-9) {
    r.lo -= 0.5;
    r.hi += 0.5;
  }
  const double pad = r.span() * fraction;
  return {r.lo - pad, r.hi + pad};
}

void putText(cv::Mat& image, const std::string& text, cv::Point at, double scale = 0.45,
             const cv::Scalar& colour = kBlack) {
  cv::putText(image, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

std::string formatTick(double value, double step) {
  char text[32];
  const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
  std::snprintf(text, sizeof(text), "%.*f", decimals, std::abs(value) < step * 1e-6 ? 0.0 : value);
  return text;
}

void drawAxes(cv::Mat& image, const Panel& p, const std::string& x_label, const std::string& y_label) {
  const double x_step = niceStep(p.x.span(), 6), y_step = niceStep(p.y.span(), 5);
  for (double v = std::ceil(p.x.lo / x_step) * x_step; v <= p.x.hi; v += x_step) {
    const cv::Point a = p.toPixel(v, p.y.lo), b = p.toPixel(v, p.y.hi);
    cv::line(image, a, b, kGrey, 1);
    putText(image, formatTick(v, x_step), a + cv::Point(-14, 18), 0.4);
  }
  for (double v = std::ceil(p.y.lo / y_step) * y_step; v <= p.y.hi; v += y_step) {
    const cv::Point a = p.toPixel(p.x.lo, v), b = p.toPixel(p.x.hi, v);
    cv::line(image, a, b, kGrey, 1);
    putText(image, formatTick(v, y_step), a + cv::Point(-52, 4), 0.4);
  }
  cv::rectangle(image, p.area, kBlack, 1);
  putText(image, x_label, {p.area.x + p.area.width / 2 - 30, p.area.y + p.area.height + 38}, 0.5);
  putText(image, y_label, {p.area.x, p.area.y - 8}, 0.5);
}

// Draws the curve through `points` (one per ATE sample), broken where consecutive samples are
// much further apart than usual, so that a stretch without estimates is not drawn as a straight
// jump. "Usual" is the median spacing: a 30 Hz TUM sequence breaks at 0.5 s, ICL-NUIM's TUM-format
// files (timestamps 1 s apart) at 5 s instead of at every sample. A lone sample is drawn as a dot.
constexpr double kMinGapS = 0.5;
double gapThreshold(const AteResult& ate) {
  std::vector<double> spacing;
  spacing.reserve(ate.samples.size());
  for (std::size_t i = 1; i < ate.samples.size(); ++i)
    spacing.push_back(ate.samples[i].timestamp_s - ate.samples[i - 1].timestamp_s);
  if (spacing.empty()) return kMinGapS;
  std::nth_element(spacing.begin(), spacing.begin() + spacing.size() / 2, spacing.end());
  return std::max(kMinGapS, 5.0 * spacing[spacing.size() / 2]);
}

void drawPolyline(cv::Mat& image, const AteResult& ate, const std::vector<cv::Point>& points,
                  const cv::Scalar& colour, int thickness) {
  const double gap_s = gapThreshold(ate);
  std::size_t start = 0;
  for (std::size_t i = 1; i <= points.size(); ++i) {
    if (i < points.size() && ate.samples[i].timestamp_s - ate.samples[i - 1].timestamp_s <= gap_s) continue;
    if (i - start >= 2) {
      const std::vector<cv::Point> piece(points.begin() + start, points.begin() + i);
      cv::polylines(image, piece, false, colour, thickness, cv::LINE_AA);
    } else if (i - start == 1) {
      cv::circle(image, points[start], thickness + 1, colour, cv::FILLED, cv::LINE_AA);
    }
    start = i;
  }
}

// The two world axes along which the ground truth moves most: the "top view" of any dataset
// convention (TUM's motion-capture z is up, ICL's y is up).
std::array<int, 2> dominantAxes(const AteResult& ate) {
  std::array<Range, 3> ranges;
  for (int a = 0; a < 3; ++a) ranges[a] = {ate.samples[0].p_world_gt[a], ate.samples[0].p_world_gt[a]};
  for (const AteSample& s : ate.samples)
    for (int a = 0; a < 3; ++a) ranges[a].include(s.p_world_gt[a]);
  std::array<int, 3> order = {0, 1, 2};
  std::sort(order.begin(), order.end(), [&](int a, int b) { return ranges[a].span() > ranges[b].span(); });
  std::array<int, 2> axes = {order[0], order[1]};
  std::sort(axes.begin(), axes.end());
  return axes;
}

void drawTopView(cv::Mat& image, const Panel& frame, const AteResult& ate) {
  const std::array<int, 2> axes = dominantAxes(ate);
  Range h{ate.samples[0].p_world_gt[axes[0]], ate.samples[0].p_world_gt[axes[0]]};
  Range v{ate.samples[0].p_world_gt[axes[1]], ate.samples[0].p_world_gt[axes[1]]};
  for (const AteSample& s : ate.samples) {
    for (const Eigen::Vector3d* p : {&s.p_world_gt, &s.p_world_est_aligned}) {
      h.include((*p)[axes[0]]);
      v.include((*p)[axes[1]]);
    }
  }
  // Equal scale on both axes so the path's shape is not distorted.
  Panel panel = frame;
  panel.x = padded(h, 0.05);
  panel.y = padded(v, 0.05);
  const double metres_per_px =
      std::max(panel.x.span() / frame.area.width, panel.y.span() / frame.area.height);
  const double cx = 0.5 * (panel.x.lo + panel.x.hi), cy = 0.5 * (panel.y.lo + panel.y.hi);
  panel.x = {cx - 0.5 * metres_per_px * frame.area.width, cx + 0.5 * metres_per_px * frame.area.width};
  panel.y = {cy - 0.5 * metres_per_px * frame.area.height, cy + 0.5 * metres_per_px * frame.area.height};
  drawAxes(image, panel, std::string(kAxisNames[axes[0]]) + " [m]",
           std::string(kAxisNames[axes[1]]) + " [m]");

  std::vector<cv::Point> gt, est;
  for (const AteSample& s : ate.samples) {
    gt.push_back(panel.toPixel(s.p_world_gt[axes[0]], s.p_world_gt[axes[1]]));
    est.push_back(panel.toPixel(s.p_world_est_aligned[axes[0]], s.p_world_est_aligned[axes[1]]));
  }
  drawPolyline(image, ate, gt, kGroundTruthColour, 2);
  drawPolyline(image, ate, est, kEstimateColour, 2);
  const cv::Point legend(frame.area.x + 10, frame.area.y + 20);
  cv::line(image, legend, legend + cv::Point(30, 0), kGroundTruthColour, 2);
  putText(image, "ground truth", legend + cv::Point(38, 5));
  cv::line(image, legend + cv::Point(0, 20), legend + cv::Point(30, 20), kEstimateColour, 2);
  putText(image, "estimate (aligned)", legend + cv::Point(38, 25));
}

void drawErrorsOverTime(cv::Mat& image, Panel panel, const AteResult& ate) {
  const double t0 = ate.samples.front().timestamp_s;
  Range t{0, ate.samples.back().timestamp_s - t0};
  Range e{0, 0};
  for (const AteSample& s : ate.samples)
    for (int a = 0; a < 3; ++a) e.include(s.p_world_est_aligned[a] - s.p_world_gt[a]);
  panel.x = padded(t, 0.0);
  panel.y = padded(e, 0.08);
  drawAxes(image, panel, "time [s]", "error (estimate - ground truth) [m]");
  for (int a = 0; a < 3; ++a) {
    std::vector<cv::Point> curve;
    for (const AteSample& s : ate.samples)
      curve.push_back(panel.toPixel(s.timestamp_s - t0, s.p_world_est_aligned[a] - s.p_world_gt[a]));
    drawPolyline(image, ate, curve, kAxisColours[a], 1);
    const cv::Point legend(panel.area.x + panel.area.width - 60, panel.area.y + 20 + 20 * a);
    cv::line(image, legend, legend + cv::Point(25, 0), kAxisColours[a], 2);
    putText(image, kAxisNames[a], legend + cv::Point(32, 5));
  }
}

bool hasPngExtension(const std::string& path) {
  if (path.size() < 4) return false;
  std::string extension = path.substr(path.size() - 4);
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension == ".png";
}

}  // namespace

Status writeTrajectoryPlot(const std::string& png_path, const AteResult& ate,
                           const TrajectoryPlotOptions& options) {
  if (ate.samples.empty()) return Status::Error(png_path + ": nothing to plot (no ATE samples)");
  if (!hasPngExtension(png_path)) return Status::Error(png_path + ": plot file name must end in .png");
  if (options.width_px < 300 || options.height_px < 400)
    return Status::Error(png_path + ": plot size too small (minimum 300x400)");
  cv::Mat image(options.height_px, options.width_px, CV_8UC3, kWhite);
  const int left = 80, right = 30, top = 60;
  const int usable_width = options.width_px - left - right;
  const int top_view_height = (options.height_px - top) * 2 / 3 - 70;
  const int error_top = top + top_view_height + 80;
  const int error_height = options.height_px - error_top - 60;
  putText(image, options.title.empty() ? "trajectory evaluation" : options.title, {left, 30}, 0.65);

  Panel top_view;
  top_view.area = cv::Rect(left, top, usable_width, top_view_height);
  drawTopView(image, top_view, ate);
  Panel errors;
  errors.area = cv::Rect(left, error_top, usable_width, error_height);
  drawErrorsOverTime(image, errors, ate);

  const Status written = writePngOutput(png_path, image, pngFastestOptions());
  if (!written.ok()) return Status::Error("cannot write plot: " + written.message());
  return Status::Ok();
}

}  // namespace plumb

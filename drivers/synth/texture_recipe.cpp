// Recording and replaying texture drawing (see texture_recipe.h).
#include "drivers/synth/texture_recipe.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <opencv2/imgproc.hpp>

#include "drivers/synth/texel_gain.h"

namespace plumb::synth {

PaintOp& TextureCanvas::add(PaintOp::Kind kind) {
  ops_->emplace_back();
  PaintOp& op = ops_->back();
  op.kind = kind;
  op.roi = roi_;
  return op;
}

void TextureCanvas::ellipse(const cv::Point& centre, const cv::Size& axes, double angle_deg, const cv::Scalar& colour,
                            int thickness, int line_type) {
  PaintOp& op = add(PaintOp::Kind::kEllipse);
  op.points[0] = centre;
  op.axes = axes;
  op.angle_deg = angle_deg;
  op.colour = colour;
  op.thickness = thickness;
  op.line_type = line_type;
}

void TextureCanvas::fillConvexPoly(const cv::Point* corners, int count, const cv::Scalar& colour, int line_type) {
  PaintOp& op = add(PaintOp::Kind::kConvexPoly);
  CV_Assert(count >= 0 && count <= 4);
  std::copy(corners, corners + count, op.points);
  op.point_count = count;
  op.colour = colour;
  op.line_type = line_type;
}

void TextureCanvas::rectangle(const cv::Rect& rect, const cv::Scalar& colour, int thickness, int line_type) {
  PaintOp& op = add(PaintOp::Kind::kRectangle);
  op.rect = rect;
  op.colour = colour;
  op.thickness = thickness;
  op.line_type = line_type;
}

void TextureCanvas::circle(const cv::Point& centre, int radius, const cv::Scalar& colour, int thickness, int line_type) {
  PaintOp& op = add(PaintOp::Kind::kCircle);
  op.points[0] = centre;
  op.radius = radius;
  op.colour = colour;
  op.thickness = thickness;
  op.line_type = line_type;
}

void TextureCanvas::line(const cv::Point& a, const cv::Point& b, const cv::Scalar& colour, int thickness, int line_type) {
  PaintOp& op = add(PaintOp::Kind::kLine);
  op.points[0] = a;
  op.points[1] = b;
  op.colour = colour;
  op.thickness = thickness;
  op.line_type = line_type;
}

void TextureCanvas::scale(const cv::Rect& rect, double gain) {
  PaintOp& op = add(PaintOp::Kind::kScale);
  op.roi = rect + roi_.tl();
  op.gain = gain;
}

TextureRecipe flatTextureRecipe(double width_m, double height_m, double texels_per_metre, const cv::Vec3f& bgr) {
  TextureRecipe recipe;
  recipe.texels_per_metre = texels_per_metre;
  recipe.cols = std::max(2, static_cast<int>(std::ceil(width_m * texels_per_metre)));
  recipe.rows = std::max(2, static_cast<int>(std::ceil(height_m * texels_per_metre)));
  recipe.base_bgr = cv::Scalar(bgr[0], bgr[1], bgr[2]);
  return recipe;
}

namespace {

void replay(const PaintOp& op, cv::Mat& bgr) {
  cv::Mat target = bgr(op.roi);
  switch (op.kind) {
    case PaintOp::Kind::kEllipse:
      cv::ellipse(target, op.points[0], op.axes, op.angle_deg, 0, 360, op.colour, op.thickness, op.line_type);
      break;
    case PaintOp::Kind::kConvexPoly:
      cv::fillConvexPoly(target, op.points, op.point_count, op.colour, op.line_type);
      break;
    case PaintOp::Kind::kRectangle:
      cv::rectangle(target, op.rect, op.colour, op.thickness, op.line_type);
      break;
    case PaintOp::Kind::kCircle:
      cv::circle(target, op.points[0], op.radius, op.colour, op.thickness, op.line_type);
      break;
    case PaintOp::Kind::kLine:
      cv::line(target, op.points[0], op.points[1], op.colour, op.thickness, op.line_type);
      break;
    case PaintOp::Kind::kScale:
      target.convertTo(target, -1, op.gain);
      break;
  }
}

// Multiplies the texture by the smoothly upsampled coarse gains (stains, uneven paint).
// bgr.setTo(colour) without cv::Mat::setTo's scratch buffer, which comes from operator new for
// rows wider than ~340 texels (a face first seen in a steady run must not allocate). The same
// bytes: each channel is saturate_cast<uchar> of the colour, as setTo converts it.
void fillTexels(cv::Mat& bgr, const cv::Scalar& colour) {
  const cv::Vec3b texel(cv::saturate_cast<uchar>(colour[0]), cv::saturate_cast<uchar>(colour[1]),
                        cv::saturate_cast<uchar>(colour[2]));
  if (bgr.rows == 0) return;
  std::fill_n(bgr.ptr<cv::Vec3b>(0), bgr.cols, texel);
  const size_t row_bytes = static_cast<size_t>(bgr.cols) * sizeof(cv::Vec3b);
  for (int y = 1; y < bgr.rows; ++y) std::memcpy(bgr.ptr(y), bgr.ptr(0), row_bytes);  // memcpy is vectorised
}

// A rows x cols view of `buffer`, grown (never shrunk) to hold it.
cv::Mat viewOf(cv::Mat& buffer, int rows, int cols, int type) {
  const size_t bytes = static_cast<size_t>(rows) * cols * CV_ELEM_SIZE(type);
  if (buffer.total() < bytes) buffer.create(1, static_cast<int>(bytes), CV_8U);
  return cv::Mat(rows, cols, type, buffer.data);
}

cv::Size shadingGainSize(const TextureRecipe& recipe) {
  return cv::Size(recipe.shading_gain_coarse.cols * recipe.shading_cell,
                  recipe.shading_gain_coarse.rows * recipe.shading_cell);
}

void applyShading(const TextureRecipe& recipe, cv::Mat& gain_buffer, cv::Mat& bgr) {
  const cv::Mat& coarse = recipe.shading_gain_coarse;
  const cv::Size size = shadingGainSize(recipe);
  cv::Mat gain = viewOf(gain_buffer, size.height, size.width, CV_32F);
  cv::resize(coarse, gain, gain.size(), 0, 0, cv::INTER_CUBIC);  // fills the view in place
  for (int r = 0; r < bgr.rows; ++r) multiplyTexels(bgr.ptr<cv::Vec3b>(r), gain.ptr<float>(r), bgr.cols);
}

}  // namespace

size_t PaintScratch::canvasBytes(const TextureRecipe& recipe) {
  if (recipe.shading_gain_coarse.empty()) return 0;  // flat light maps use no scratch
  return static_cast<size_t>(recipe.rows) * recipe.cols * 3;
}

size_t PaintScratch::gainBytes(const TextureRecipe& recipe) {
  if (recipe.shading_gain_coarse.empty()) return 0;
  return static_cast<size_t>(shadingGainSize(recipe).area()) * sizeof(float);
}

void paintTexture(const TextureRecipe& recipe, PaintScratch& scratch, cv::Mat& bgr) {
  const bool procedural = !recipe.shading_gain_coarse.empty();
  // Procedural textures are drawn in the scratch canvas and blurred into bgr; a flat light map
  // is just its colour.
  bgr.create(recipe.rows, recipe.cols, CV_8UC3);
  cv::Mat canvas = procedural ? viewOf(scratch.canvas, recipe.rows, recipe.cols, CV_8UC3) : bgr;
  fillTexels(canvas, recipe.base_bgr);
  for (const PaintOp& op : recipe.ops) replay(op, canvas);
  if (!procedural) return;
  applyShading(recipe, scratch.gain, canvas);
  // Band-limit: no detail finer than ~2 texels, so distant views do not alias.
  cv::GaussianBlur(canvas, bgr, cv::Size(0, 0), 0.7);
}

}  // namespace plumb::synth

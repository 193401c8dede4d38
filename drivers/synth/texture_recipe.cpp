// Recording and replaying texture drawing (see texture_recipe.h).
#include "drivers/synth/texture_recipe.h"

#include <algorithm>
#include <cmath>

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
void applyShading(const TextureRecipe& recipe, cv::Mat& bgr) {
  const cv::Mat& coarse = recipe.shading_gain_coarse;
  const int cell = recipe.shading_cell;
  cv::Mat gain;
  cv::resize(coarse, gain, cv::Size(coarse.cols * cell, coarse.rows * cell), 0, 0, cv::INTER_CUBIC);
  for (int r = 0; r < bgr.rows; ++r) multiplyTexels(bgr.ptr<cv::Vec3b>(r), gain.ptr<float>(r), bgr.cols);
}

}  // namespace

void paintTexture(const TextureRecipe& recipe, cv::Mat& bgr) {
  bgr.create(recipe.rows, recipe.cols, CV_8UC3);
  bgr.setTo(recipe.base_bgr);
  for (const PaintOp& op : recipe.ops) replay(op, bgr);
  if (recipe.shading_gain_coarse.empty()) return;  // a flat light map
  applyShading(recipe, bgr);
  // Band-limit: no detail finer than ~2 texels, so distant views do not alias.
  cv::GaussianBlur(bgr, bgr, cv::Size(0, 0), 0.7);
}

}  // namespace plumb::synth

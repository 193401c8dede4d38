// Procedural surface textures (see surface_texture.h). Only OpenCV drawing calls (recorded, then
// replayed by paintTexture) and our own SplitMix64 draws are used, so a seed always produces the
// same texels.
#include "drivers/synth/surface_texture.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>  // cv::FILLED, cv::LINE_AA

namespace plumb::synth {
namespace {

// Every draw below is its own statement: C++ leaves the evaluation order of function (and
// constructor) arguments unspecified, GCC evaluates them right to left on x86-64 and left to right
// on aarch64, so `cv::Point(rng.uniformInt(..), rng.uniformInt(..))` gave different textures on the
// two (docs/EMBEDDED.md). The statements keep the order x86-64 builds always used (last argument
// first), so existing scenes keep their bytes.
cv::Scalar randomColour(SplitMix64& rng, double lo = 20, double hi = 235) {
  const double red = rng.uniform(lo, hi);
  const double green = rng.uniform(lo, hi);
  const double blue = rng.uniform(lo, hi);
  return cv::Scalar(blue, green, red);
}

// Smooth brightness variations of about +-15% (stains, uneven paint), multiplied in at painting.
void drawLowFrequencyShading(TextureRecipe& recipe, double texels_per_metre, SplitMix64& rng) {
  const int cell = std::max(4, static_cast<int>(0.25 * texels_per_metre));  // ~25 cm features
  cv::Mat coarse(recipe.rows / cell + 2, recipe.cols / cell + 2, CV_32F);
  for (int r = 0; r < coarse.rows; ++r)
    for (int c = 0; c < coarse.cols; ++c) coarse.at<float>(r, c) = static_cast<float>(rng.uniform(0.85, 1.15));
  recipe.shading_gain_coarse = coarse;
  recipe.shading_cell = cell;
}

void drawBlobs(TextureCanvas& canvas, double tpm, double per_m2, double min_m, double max_m, SplitMix64& rng) {
  const double area_m2 = canvas.cols * canvas.rows / (tpm * tpm);
  const int count = static_cast<int>(area_m2 * per_m2);
  for (int i = 0; i < count; ++i) {
    const int centre_y = rng.uniformInt(0, canvas.rows - 1);
    const int centre_x = rng.uniformInt(0, canvas.cols - 1);
    const cv::Point centre(centre_x, centre_y);
    const int axis_v = std::max(2, static_cast<int>(rng.uniform(min_m, max_m) * tpm));
    const int axis_u = std::max(2, static_cast<int>(rng.uniform(min_m, max_m) * tpm));
    const cv::Size axes(axis_u, axis_v);
    const double angle = rng.uniform(0, 180);
    if (rng.uniform() < 0.7) {
      canvas.ellipse(centre, axes, angle, randomColour(rng), cv::FILLED, cv::LINE_AA);
    } else {  // rotated squares and triangles give sharp corners
      const int sides = rng.uniform() < 0.5 ? 3 : 4;
      cv::Point corners[4];
      for (int k = 0; k < sides; ++k) {
        const double a = angle * M_PI / 180 + 2 * M_PI * k / sides;
        corners[k] = centre + cv::Point(static_cast<int>(axes.width * std::cos(a)),
                                        static_cast<int>(axes.width * std::sin(a)));
      }
      canvas.fillConvexPoly(corners, sides, randomColour(rng), cv::LINE_AA);
    }
  }
}

void drawCheckerPatch(TextureCanvas& canvas, double tpm, SplitMix64& rng) {
  const int square = std::max(3, static_cast<int>(rng.uniform(0.03, 0.07) * tpm));
  const int nx = rng.uniformInt(3, 8), ny = rng.uniformInt(3, 8);
  const int x0 = rng.uniformInt(0, std::max(0, canvas.cols - nx * square));
  const int y0 = rng.uniformInt(0, std::max(0, canvas.rows - ny * square));
  const cv::Scalar dark = randomColour(rng, 10, 90), light = randomColour(rng, 160, 250);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      canvas.rectangle(cv::Rect(x0 + i * square, y0 + j * square, square, square), (i + j) % 2 ? dark : light,
                    cv::FILLED);
}

// A framed rectangle with stripes, discs or bars inside.
void drawPoster(TextureCanvas& canvas, double tpm, SplitMix64& rng) {
  const int w = static_cast<int>(rng.uniform(0.3, 0.9) * tpm), h = static_cast<int>(rng.uniform(0.3, 0.8) * tpm);
  if (w >= canvas.cols || h >= canvas.rows) return;
  const int top = rng.uniformInt(0, canvas.rows - h - 1);
  const int left = rng.uniformInt(0, canvas.cols - w - 1);
  const cv::Rect rect(left, top, w, h);
  canvas.rectangle(rect, randomColour(rng, 60, 240), cv::FILLED);
  TextureCanvas inner = canvas.region(rect);
  const int kind = rng.uniformInt(0, 2);
  const int items = rng.uniformInt(6, 16);
  for (int i = 0; i < items; ++i) {
    const cv::Scalar colour = randomColour(rng);
    if (kind == 0) {
      const int y = rng.uniformInt(0, h - 1), t = rng.uniformInt(2, std::max(3, h / 10));
      inner.rectangle(cv::Rect(0, y, w, t), colour, cv::FILLED);
    } else if (kind == 1) {
      const int radius = rng.uniformInt(3, std::max(4, w / 6));
      const int cy = rng.uniformInt(0, h - 1);
      const int cx = rng.uniformInt(0, w - 1);
      inner.circle(cv::Point(cx, cy), radius, colour, cv::FILLED, cv::LINE_AA);
    } else {  // "text": short dark bars in rows
      const int y = rng.uniformInt(0, h - 1), x = rng.uniformInt(0, w - 1);
      const cv::Scalar ink = randomColour(rng, 0, 70);
      const int length = rng.uniformInt(4, std::max(5, w / 3));
      inner.rectangle(cv::Rect(x, y, length, std::max(2, h / 25)), ink, cv::FILLED);
    }
  }
  canvas.rectangle(rect, randomColour(rng, 0, 60), std::max(2, static_cast<int>(0.015 * tpm)));
}

void drawTiles(TextureCanvas& canvas, double tpm, SplitMix64& rng) {
  const int tile = static_cast<int>(rng.uniform(0.3, 0.5) * tpm);
  const cv::Scalar grout = randomColour(rng, 40, 110);
  for (int y = 0; y < canvas.rows; y += tile)
    for (int x = 0; x < canvas.cols; x += tile) {
      const double gain = rng.uniform(0.85, 1.15);  // each tile its own shade
      canvas.scale(cv::Rect(x, y, std::min(tile, canvas.cols - x), std::min(tile, canvas.rows - y)), gain);
    }
  for (int y = 0; y < canvas.rows; y += tile) canvas.line({0, y}, {canvas.cols - 1, y}, grout, 2, cv::LINE_AA);
  for (int x = 0; x < canvas.cols; x += tile) canvas.line({x, 0}, {x, canvas.rows - 1}, grout, 2, cv::LINE_AA);
}

void drawStripes(TextureCanvas& canvas, double tpm, SplitMix64& rng) {
  const int count = rng.uniformInt(2, 6);
  for (int i = 0; i < count; ++i) {
    const int t = std::max(2, static_cast<int>(rng.uniform(0.01, 0.05) * tpm));
    if (rng.uniform() < 0.5) {
      const int y = rng.uniformInt(0, canvas.rows - 1);
      canvas.rectangle(cv::Rect(0, y, canvas.cols, t), randomColour(rng), cv::FILLED);
    } else {
      const int x = rng.uniformInt(0, canvas.cols - 1);
      canvas.rectangle(cv::Rect(x, 0, t, canvas.rows), randomColour(rng), cv::FILLED);
    }
  }
}

}  // namespace

TextureRecipe planSurfaceTexture(double width_m, double height_m, double tpm, TextureStyle style,
                                 const cv::Vec3f& base_bgr, SplitMix64& rng) {
  TextureRecipe recipe = flatTextureRecipe(width_m, height_m, tpm, base_bgr);
  TextureCanvas canvas(&recipe.ops, cv::Rect(0, 0, recipe.cols, recipe.rows));
  const double area_m2 = width_m * height_m;
  switch (style) {
    case TextureStyle::kWall:
      drawBlobs(canvas, tpm, 10, 0.02, 0.10, rng);
      for (int i = static_cast<int>(area_m2 / 4) + 1; i > 0; --i) drawPoster(canvas, tpm, rng);
      for (int i = static_cast<int>(area_m2 / 6) + 1; i > 0; --i) drawCheckerPatch(canvas, tpm, rng);
      break;
    case TextureStyle::kFloor:
      drawTiles(canvas, tpm, rng);
      drawBlobs(canvas, tpm, 6, 0.015, 0.06, rng);
      break;
    case TextureStyle::kObject:
      drawStripes(canvas, tpm, rng);
      drawBlobs(canvas, tpm, 40, 0.01, 0.05, rng);
      if (area_m2 > 0.1) drawCheckerPatch(canvas, tpm, rng);
      break;
    case TextureStyle::kRug:
      drawCheckerPatch(canvas, tpm, rng);
      drawBlobs(canvas, tpm, 25, 0.03, 0.12, rng);
      break;
    case TextureStyle::kCeiling:
      break;
  }
  drawLowFrequencyShading(recipe, tpm, rng);
  return recipe;
}

}  // namespace plumb::synth

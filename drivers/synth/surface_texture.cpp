// Procedural surface textures (see surface_texture.h). Only OpenCV drawing calls and our own
// SplitMix64 draws are used, so a seed always produces the same texels.
#include "drivers/synth/surface_texture.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

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

// Multiplies the texture by smooth brightness variations of about +-15% (stains, uneven paint).
void applyLowFrequencyShading(cv::Mat& bgr, double texels_per_metre, SplitMix64& rng) {
  const int cell = std::max(4, static_cast<int>(0.25 * texels_per_metre));  // ~25 cm features
  cv::Mat coarse(bgr.rows / cell + 2, bgr.cols / cell + 2, CV_32F);
  for (int r = 0; r < coarse.rows; ++r)
    for (int c = 0; c < coarse.cols; ++c) coarse.at<float>(r, c) = static_cast<float>(rng.uniform(0.85, 1.15));
  cv::Mat gain;
  cv::resize(coarse, gain, cv::Size(coarse.cols * cell, coarse.rows * cell), 0, 0, cv::INTER_CUBIC);
  for (int r = 0; r < bgr.rows; ++r) {
    cv::Vec3b* row = bgr.ptr<cv::Vec3b>(r);
    const float* g = gain.ptr<float>(r);
    for (int c = 0; c < bgr.cols; ++c)
      for (int k = 0; k < 3; ++k) row[c][k] = cv::saturate_cast<uchar>(row[c][k] * g[c]);
  }
}

void drawBlobs(cv::Mat& bgr, double tpm, double per_m2, double min_m, double max_m, SplitMix64& rng) {
  const double area_m2 = bgr.cols * bgr.rows / (tpm * tpm);
  const int count = static_cast<int>(area_m2 * per_m2);
  for (int i = 0; i < count; ++i) {
    const int centre_y = rng.uniformInt(0, bgr.rows - 1);
    const int centre_x = rng.uniformInt(0, bgr.cols - 1);
    const cv::Point centre(centre_x, centre_y);
    const int axis_v = std::max(2, static_cast<int>(rng.uniform(min_m, max_m) * tpm));
    const int axis_u = std::max(2, static_cast<int>(rng.uniform(min_m, max_m) * tpm));
    const cv::Size axes(axis_u, axis_v);
    const double angle = rng.uniform(0, 180);
    if (rng.uniform() < 0.7) {
      cv::ellipse(bgr, centre, axes, angle, 0, 360, randomColour(rng), cv::FILLED, cv::LINE_AA);
    } else {  // rotated squares and triangles give sharp corners
      const int sides = rng.uniform() < 0.5 ? 3 : 4;
      cv::Point corners[4];
      for (int k = 0; k < sides; ++k) {
        const double a = angle * M_PI / 180 + 2 * M_PI * k / sides;
        corners[k] = centre + cv::Point(static_cast<int>(axes.width * std::cos(a)),
                                        static_cast<int>(axes.width * std::sin(a)));
      }
      cv::fillConvexPoly(bgr, corners, sides, randomColour(rng), cv::LINE_AA);
    }
  }
}

void drawCheckerPatch(cv::Mat& bgr, double tpm, SplitMix64& rng) {
  const int square = std::max(3, static_cast<int>(rng.uniform(0.03, 0.07) * tpm));
  const int nx = rng.uniformInt(3, 8), ny = rng.uniformInt(3, 8);
  const int x0 = rng.uniformInt(0, std::max(0, bgr.cols - nx * square));
  const int y0 = rng.uniformInt(0, std::max(0, bgr.rows - ny * square));
  const cv::Scalar dark = randomColour(rng, 10, 90), light = randomColour(rng, 160, 250);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      cv::rectangle(bgr, cv::Rect(x0 + i * square, y0 + j * square, square, square),
                    (i + j) % 2 ? dark : light, cv::FILLED);
}

// A framed rectangle with stripes, discs or bars inside.
void drawPoster(cv::Mat& bgr, double tpm, SplitMix64& rng) {
  const int w = static_cast<int>(rng.uniform(0.3, 0.9) * tpm), h = static_cast<int>(rng.uniform(0.3, 0.8) * tpm);
  if (w >= bgr.cols || h >= bgr.rows) return;
  const int top = rng.uniformInt(0, bgr.rows - h - 1);
  const int left = rng.uniformInt(0, bgr.cols - w - 1);
  const cv::Rect rect(left, top, w, h);
  cv::rectangle(bgr, rect, randomColour(rng, 60, 240), cv::FILLED);
  cv::Mat inner = bgr(rect);
  const int kind = rng.uniformInt(0, 2);
  const int items = rng.uniformInt(6, 16);
  for (int i = 0; i < items; ++i) {
    const cv::Scalar colour = randomColour(rng);
    if (kind == 0) {
      const int y = rng.uniformInt(0, h - 1), t = rng.uniformInt(2, std::max(3, h / 10));
      cv::rectangle(inner, cv::Rect(0, y, w, t), colour, cv::FILLED);
    } else if (kind == 1) {
      const int radius = rng.uniformInt(3, std::max(4, w / 6));
      const int cy = rng.uniformInt(0, h - 1);
      const int cx = rng.uniformInt(0, w - 1);
      cv::circle(inner, cv::Point(cx, cy), radius, colour, cv::FILLED, cv::LINE_AA);
    } else {  // "text": short dark bars in rows
      const int y = rng.uniformInt(0, h - 1), x = rng.uniformInt(0, w - 1);
      const cv::Scalar ink = randomColour(rng, 0, 70);
      const int length = rng.uniformInt(4, std::max(5, w / 3));
      cv::rectangle(inner, cv::Rect(x, y, length, std::max(2, h / 25)), ink, cv::FILLED);
    }
  }
  cv::rectangle(bgr, rect, randomColour(rng, 0, 60), std::max(2, static_cast<int>(0.015 * tpm)));
}

void drawTiles(cv::Mat& bgr, double tpm, SplitMix64& rng) {
  const int tile = static_cast<int>(rng.uniform(0.3, 0.5) * tpm);
  const cv::Scalar grout = randomColour(rng, 40, 110);
  for (int y = 0; y < bgr.rows; y += tile)
    for (int x = 0; x < bgr.cols; x += tile) {
      const double gain = rng.uniform(0.85, 1.15);  // each tile its own shade
      cv::Mat t = bgr(cv::Rect(x, y, std::min(tile, bgr.cols - x), std::min(tile, bgr.rows - y)));
      t.convertTo(t, -1, gain);
    }
  for (int y = 0; y < bgr.rows; y += tile) cv::line(bgr, {0, y}, {bgr.cols - 1, y}, grout, 2, cv::LINE_AA);
  for (int x = 0; x < bgr.cols; x += tile) cv::line(bgr, {x, 0}, {x, bgr.rows - 1}, grout, 2, cv::LINE_AA);
}

void drawStripes(cv::Mat& bgr, double tpm, SplitMix64& rng) {
  const int count = rng.uniformInt(2, 6);
  for (int i = 0; i < count; ++i) {
    const int t = std::max(2, static_cast<int>(rng.uniform(0.01, 0.05) * tpm));
    if (rng.uniform() < 0.5) {
      const int y = rng.uniformInt(0, bgr.rows - 1);
      cv::rectangle(bgr, cv::Rect(0, y, bgr.cols, t), randomColour(rng), cv::FILLED);
    } else {
      const int x = rng.uniformInt(0, bgr.cols - 1);
      cv::rectangle(bgr, cv::Rect(x, 0, t, bgr.rows), randomColour(rng), cv::FILLED);
    }
  }
}

}  // namespace

SurfaceTexture makeSurfaceTexture(double width_m, double height_m, double tpm, TextureStyle style,
                                  const cv::Vec3f& base_bgr, SplitMix64& rng) {
  SurfaceTexture texture;
  texture.texels_per_metre = tpm;
  const int cols = std::max(2, static_cast<int>(std::ceil(width_m * tpm)));
  const int rows = std::max(2, static_cast<int>(std::ceil(height_m * tpm)));
  texture.bgr.create(rows, cols, CV_8UC3);
  texture.bgr.setTo(cv::Scalar(base_bgr[0], base_bgr[1], base_bgr[2]));
  cv::Mat& bgr = texture.bgr;
  const double area_m2 = width_m * height_m;
  switch (style) {
    case TextureStyle::kWall:
      drawBlobs(bgr, tpm, 10, 0.02, 0.10, rng);
      for (int i = static_cast<int>(area_m2 / 4) + 1; i > 0; --i) drawPoster(bgr, tpm, rng);
      for (int i = static_cast<int>(area_m2 / 6) + 1; i > 0; --i) drawCheckerPatch(bgr, tpm, rng);
      break;
    case TextureStyle::kFloor:
      drawTiles(bgr, tpm, rng);
      drawBlobs(bgr, tpm, 6, 0.015, 0.06, rng);
      break;
    case TextureStyle::kObject:
      drawStripes(bgr, tpm, rng);
      drawBlobs(bgr, tpm, 40, 0.01, 0.05, rng);
      if (area_m2 > 0.1) drawCheckerPatch(bgr, tpm, rng);
      break;
    case TextureStyle::kRug:
      drawCheckerPatch(bgr, tpm, rng);
      drawBlobs(bgr, tpm, 25, 0.03, 0.12, rng);
      break;
    case TextureStyle::kCeiling:
      break;
  }
  applyLowFrequencyShading(bgr, tpm, rng);
  // Band-limit: no detail finer than ~2 texels, so distant views do not alias.
  cv::GaussianBlur(bgr, bgr, cv::Size(0, 0), 0.7);
  return texture;
}

}  // namespace plumb::synth

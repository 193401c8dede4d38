#pragma once
// A face texture before it is painted: its size, base colour and every random draw, recorded as a
// list of drawing operations. Recording costs a few hundred draws per face; painting (OpenCV
// drawing, shading, blur) costs millions of instructions for a wall, so the scenes record every
// recipe when they are built (the draws come from one sequential generator, whose order must not
// depend on which faces a frame sees) and paint a face only when a frame first sees it
// (baked_textures.h). paintTexture replays the operations in order on a blank image, so a recipe
// gives the same texels as drawing straight away did.
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace plumb::synth {

// One recorded drawing call. Every operation acts on the sub-image `roi` (clipped to it, as
// OpenCV clips drawing on a cv::Mat ROI); coordinates are relative to roi's corner.
struct PaintOp {
  enum class Kind { kEllipse, kConvexPoly, kRectangle, kCircle, kLine, kScale };
  Kind kind = Kind::kRectangle;
  cv::Rect roi;
  cv::Point points[4];      // ellipse/circle: centre; line: both ends; polygon: corners
  int point_count = 0;      // corners of a polygon
  cv::Size axes;            // ellipse
  double angle_deg = 0;     // ellipse
  int radius = 0;           // circle
  cv::Rect rect;            // rectangle
  cv::Scalar colour;
  int thickness = 1;        // cv::FILLED or a line width
  int line_type = 8;        // cv::LINE_8 or cv::LINE_AA
  double gain = 1;          // kScale: roi = roi * gain (saturated)
};

// Records drawing calls with the signatures of OpenCV's, so that texture code reads as if it drew.
// A canvas is a view: region() gives a canvas for a sub-rectangle writing into the same list.
class TextureCanvas {
 public:
  TextureCanvas(std::vector<PaintOp>* ops, const cv::Rect& roi)
      : rows(roi.height), cols(roi.width), ops_(ops), roi_(roi) {}

  const int rows, cols;  // of the (sub-)image this canvas draws on

  TextureCanvas region(const cv::Rect& rect) const { return TextureCanvas(ops_, rect + roi_.tl()); }

  void ellipse(const cv::Point& centre, const cv::Size& axes, double angle_deg, const cv::Scalar& colour,
               int thickness, int line_type);
  void fillConvexPoly(const cv::Point* corners, int count, const cv::Scalar& colour, int line_type);
  void rectangle(const cv::Rect& rect, const cv::Scalar& colour, int thickness, int line_type = 8);
  void circle(const cv::Point& centre, int radius, const cv::Scalar& colour, int thickness, int line_type);
  void line(const cv::Point& a, const cv::Point& b, const cv::Scalar& colour, int thickness, int line_type);
  // Multiplies the texels of `rect` by gain (cv::Mat::convertTo with alpha = gain).
  void scale(const cv::Rect& rect, double gain);

 private:
  PaintOp& add(PaintOp::Kind kind);

  std::vector<PaintOp>* ops_;
  cv::Rect roi_;  // in the whole texture
};

struct TextureRecipe {
  TextureRecipe() = default;
  TextureRecipe(const TextureRecipe&) = default;
  TextureRecipe& operator=(const TextureRecipe&) = default;
  TextureRecipe& operator=(TextureRecipe&&) = default;
  // cv::Mat's move constructor is not declared noexcept (OpenCV 4.6), so without this std::vector
  // COPIED every recipe (ops and all) each time a scene's recipe list grew: ~500 page faults and
  // a few ms before the first synthetic frame. Moving a Mat only hands over its pointers.
  TextureRecipe(TextureRecipe&& other) noexcept { *this = std::move(other); }

  int rows = 2, cols = 2;
  double texels_per_metre = 0;
  cv::Scalar base_bgr;           // the whole image starts in this colour
  std::vector<PaintOp> ops;      // then these are drawn, in order
  // Procedural textures only (empty for flat light maps): a coarse grid of brightness gains,
  // each covering shading_cell x shading_cell texels, smoothly (bicubically) upsampled and
  // multiplied in after the drawing; then a light blur band-limits the texture.
  cv::Mat shading_gain_coarse;   // CV_32F
  int shading_cell = 0;
};

// A recipe of a plain face, width_m x height_m at texels_per_metre, in one colour.
TextureRecipe flatTextureRecipe(double width_m, double height_m, double texels_per_metre, const cv::Vec3f& bgr);

// Buffers that painting reuses from texture to texture (they grow to the largest), so that
// painting a scene does not touch fresh memory, page fault after page fault, for every face.
struct PaintScratch {
  // Bytes of each buffer that painting `recipe` needs (0 for a flat light map).
  static size_t canvasBytes(const TextureRecipe& recipe);
  static size_t gainBytes(const TextureRecipe& recipe);

  cv::Mat canvas;  // the texture before its blur (bytes, one row)
  cv::Mat gain;    // the upsampled shading gains (bytes, one row)
};

// Paints the recipe into bgr (CV_8UC3; reallocated unless it is rows x cols already).
void paintTexture(const TextureRecipe& recipe, PaintScratch& scratch, cv::Mat& bgr);

}  // namespace plumb::synth

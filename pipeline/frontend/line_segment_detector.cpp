#include "pipeline/frontend/line_segment_detector.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <opencv2/core/hal/intrin.hpp>

#include "pipeline/frontend/lsd_kernels.h"

namespace plumb {
namespace {

constexpr int kBins = 1024;
constexpr uint8_t kFree = kLsdFree, kUsed = kLsdUsed;
// The region growing reads the states of the 3x3 neighbourhood as three little-endian words
// (p - w - 1 .. p - w + 2, p - 1 .. p + 2, p + w - 1 .. p + w + 2), so the state array has a used
// row and one byte before pixel 0 (stateFront) and three bytes after the last pixel.
constexpr int kStateBack = 3;
int stateFront(int width) { return width + 1; }
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "neighbour masks read states as little-endian words");

// Neighbours by bit of lsdNeighbourMask (bits 3, 7, 11 never set): raster order, a row a nibble.
constexpr int8_t kNeighbourDx[12] = {-1, 0, 1, 0, -1, 0, 1, 0, -1, 0, 1, 0};
constexpr int8_t kNeighbourDy[12] = {-1, -1, -1, 0, 0, 0, 0, 0, 1, 1, 1, 0};

// A step (dx, dy) as the 32-bit word that, added to a region pixel's (x, y) word (x the low
// int16 half), adds both coordinates at once: exact while x + dx stays >= 0 (no borrow).
uint32_t packedStep(int dx, int dy) { return static_cast<uint32_t>(dx + dy * 65536); }

// The states of 4 pixels from the 4-bit mask of which are above the threshold (bit i: pixel i).
struct StateBytes {
  uint8_t state[4];
};
constexpr StateBytes stateBytes(int mask) {
  StateBytes b{};
  for (int i = 0; i < 4; ++i) b.state[i] = (mask >> i) & 1 ? kFree : kUsed;
  return b;
}
constexpr StateBytes kStateBytes[16] = {stateBytes(0),  stateBytes(1),  stateBytes(2),  stateBytes(3),
                                        stateBytes(4),  stateBytes(5),  stateBytes(6),  stateBytes(7),
                                        stateBytes(8),  stateBytes(9),  stateBytes(10), stateBytes(11),
                                        stateBytes(12), stateBytes(13), stateBytes(14), stateBytes(15)};

}  // namespace

LineSegmentDetector::LineSegmentDetector(int max_width, int max_height, const LineSegmentDetectorOptions& options)
    : options_(options), max_width_(max_width), max_height_(max_height) {
  CV_Assert(max_width < 32768 && max_height < 32768);  // region coordinates are int16
  const size_t n = static_cast<size_t>(max_width) * max_height;
  magnitude_.resize(n);
  dir_x_.resize(n);
  dir_y_.resize(n);
  state_.resize(n + stateFront(max_width) + kStateBack, kUsed);
  bucket_start_.resize(kBins + 1);
  ordered_.resize(n);
  region_.resize(n);
  region_xy_.resize(n);
  candidate_.resize(n);
  candidate_bin_.resize(n);
}

int LineSegmentDetector::detect(const cv::Mat& image, float min_length, DetectedSegment* out, int capacity) {
  CV_Assert(image.type() == CV_8UC1 && image.cols <= max_width_ && image.rows <= max_height_);
  width_ = image.cols;
  height_ = image.rows;
  const int w = width_, h = height_;
  const float tau = options_.angle_tolerance_deg * static_cast<float>(M_PI) / 180.f;
  const float threshold = options_.quantization / std::sin(tau);
  const float cos_tau = std::cos(tau);

  // 2x2 gradient at (x + 0.5, y + 0.5); the last row and column have none. Eight pixels per
  // step: the doubled gradient 2 gx = b + d - a - c (|.| <= 510) in int16 lanes, its squared
  // norm 4 (gx^2 + gy^2) <= 520,200 from one multiply-add of (2 gx, 2 gy) pairs in int32, then
  // float lanes. Every value is exactly the scalar tail's: 0.5 * (2 gx) and the sum of squares
  // are exact in float either way (quarter units below 2^24), and sqrt and division are
  // correctly rounded.
  const cv::v_float32x4 v_half = cv::v_setall_f32(0.5f), v_quarter = cv::v_setall_f32(0.25f);
  const cv::v_float32x4 v_one = cv::v_setall_f32(1.f), v_zero = cv::v_setzero_f32();
  const cv::v_float32x4 v_threshold = cv::v_setall_f32(threshold);
  cv::v_float32x4 v_max = cv::v_setzero_f32();
  float max_magnitude = 0;
  for (int y = 0; y < h; ++y) {
    float* mag = magnitude_.data() + y * w;
    float* ux = dir_x_.data() + y * w;
    float* uy = dir_y_.data() + y * w;
    uint8_t* st = state_.data() + stateFront(w) + y * w;
    if (y == h - 1) {
      std::fill_n(mag, w, 0.f);
      std::fill_n(st, w, kUsed);
      break;
    }
    const uint8_t* r0 = image.ptr<uint8_t>(y);
    const uint8_t* r1 = image.ptr<uint8_t>(y + 1);
    // Four pixels' magnitude, unit direction, states and running maximum from their doubled
    // gradients (int32 lanes) and squared norms.
    auto finish = [&](int x, const cv::v_int32x4& gx2, const cv::v_int32x4& gy2, const cv::v_int32x4& norm2) {
      const cv::v_float32x4 gx = v_half * cv::v_cvt_f32(gx2), gy = v_half * cv::v_cvt_f32(gy2);
      const cv::v_float32x4 m = cv::v_sqrt(cv::v_cvt_f32(norm2) * v_quarter);
      const cv::v_float32x4 inv = cv::v_select(m > v_zero, v_one / m, v_zero);
      cv::v_store(mag + x, m);
      cv::v_store(ux + x, gx * inv);
      cv::v_store(uy + x, gy * inv);
      std::memcpy(st + x, &kStateBytes[cv::v_signmask(m > v_threshold)], 4);
      v_max = cv::v_max(v_max, m);
    };
    int x = 0;
    for (; x + 8 < w; x += 8) {  // reads x .. x + 8: stays inside the row
      const cv::v_int16x8 a = cv::v_reinterpret_as_s16(cv::v_load_expand(r0 + x));
      const cv::v_int16x8 b = cv::v_reinterpret_as_s16(cv::v_load_expand(r0 + x + 1));
      const cv::v_int16x8 c = cv::v_reinterpret_as_s16(cv::v_load_expand(r1 + x));
      const cv::v_int16x8 d = cv::v_reinterpret_as_s16(cv::v_load_expand(r1 + x + 1));
      const cv::v_int16x8 gx2 = b + d - a - c, gy2 = c + d - a - b;  // no saturation: |.| <= 510
      cv::v_int16x8 pairs_lo, pairs_hi;
      cv::v_zip(gx2, gy2, pairs_lo, pairs_hi);
      cv::v_int32x4 gx2_lo, gx2_hi, gy2_lo, gy2_hi;
      cv::v_expand(gx2, gx2_lo, gx2_hi);
      cv::v_expand(gy2, gy2_lo, gy2_hi);
      finish(x, gx2_lo, gy2_lo, cv::v_dotprod(pairs_lo, pairs_lo));
      finish(x + 4, gx2_hi, gy2_hi, cv::v_dotprod(pairs_hi, pairs_hi));
    }
    for (; x < w - 1; ++x) {
      const int a = r0[x], b = r0[x + 1], c = r1[x], d = r1[x + 1];
      const float gx = 0.5f * static_cast<float>(b + d - a - c);
      const float gy = 0.5f * static_cast<float>(c + d - a - b);
      const float m = std::sqrt(gx * gx + gy * gy);
      mag[x] = m;
      const float inv = m > 0 ? 1.f / m : 0.f;
      ux[x] = gx * inv;
      uy[x] = gy * inv;
      st[x] = m > threshold ? kFree : kUsed;
      max_magnitude = std::max(max_magnitude, m);
    }
    mag[w - 1] = 0;
    st[w - 1] = kUsed;
  }
  max_magnitude = std::max(max_magnitude, cv::v_reduce_max(v_max));
  if (max_magnitude <= threshold) return 0;

  // Bucket sort of candidate pixels by magnitude, strongest bucket first, stable in raster
  // order. One pass over the image collects candidates and their bins, the second only the
  // candidates. Hot loops use local pointers: stores to the uint8_t state may alias anything,
  // which would make the compiler reload every vector's data pointer.
  const float bin_scale = (kBins - 1) / max_magnitude;
  int* bucket_start = bucket_start_.data();
  std::fill_n(bucket_start, kBins + 1, 0);
  const int n = w * h;
  const float* magnitude = magnitude_.data();
  const float* dir_x = dir_x_.data();
  const float* dir_y = dir_y_.data();
  uint8_t* state = state_.data() + stateFront(w);
  std::fill_n(state - stateFront(w), stateFront(w), kUsed);  // the row above (a wider image may have written it)
  int* candidate = candidate_.data();
  uint16_t* candidate_bin = candidate_bin_.data();
  int candidates = 0;
  auto collect = [&](int i) {
    const int bin = kBins - 1 - static_cast<int>(magnitude[i] * bin_scale);
    candidate[candidates] = i;
    candidate_bin[candidates++] = static_cast<uint16_t>(bin);
    ++bucket_start[bin + 1];
  };
  // 16 states a step as a bit mask of the free ones (a third of a Kinect frame's pixels are
  // candidates: fewer tests and no branch per pixel), in raster order.
  const cv::v_uint8x16 v_free = cv::v_setall_u8(kFree);
  int i = 0;
  for (; i + 16 <= n; i += 16) {
    uint32_t mask = static_cast<uint32_t>(cv::v_signmask(cv::v_load(state + i) == v_free));
    while (mask != 0) {
      collect(i + __builtin_ctz(mask));
      mask &= mask - 1;
    }
  }
  for (; i < n; ++i) {
    if (state[i] == kFree) collect(i);
  }
  for (int b = 0; b < kBins; ++b) bucket_start[b + 1] += bucket_start[b];
  int* ordered = ordered_.data();
  for (int k = 0; k < candidates; ++k) ordered[bucket_start[candidate_bin[k]]++] = candidate[k];

  // Offsets and packed (x, y) steps of the neighbours by mask bit (lsd_kernels.h).
  int neighbour_offset[12];
  uint32_t neighbour_step[12];
  for (int bit = 0; bit < 12; ++bit) {
    neighbour_offset[bit] = kNeighbourDy[bit] * w + kNeighbourDx[bit];
    neighbour_step[bit] = packedStep(kNeighbourDx[bit], kNeighbourDy[bit]);
  }
  int* region = region_.data();
  RegionPixel* region_xy = region_xy_.data();
  int count = 0;
  for (int k = 0; k < candidates && count < capacity; ++k) {
    const int seed = ordered[k];
    if (state[seed] != kFree) continue;
    // Grow the region; its direction is the running (unnormalised) sum of unit gradients, whose
    // norm (and so the alignment bound) only changes when a pixel joins.
    state[seed] = kUsed;
    region[0] = seed;
    region_xy[0] = RegionPixel{static_cast<int16_t>(seed % w), static_cast<int16_t>(seed / w)};
    int size = 1;
    float sum_x = dir_x[seed], sum_y = dir_y[seed];
    float bound = cos_tau * std::sqrt(sum_x * sum_x + sum_y * sum_y);
    // The free neighbours as a bit mask (lsd_kernels.h); its set bits are visited in the order a
    // plain 3x3 loop would (a neighbour can only change state when it is the one being added).
    for (int r = 0; r < size; ++r) {
      const int p = region[r];
      uint32_t pixel_xy;
      std::memcpy(&pixel_xy, &region_xy[r], sizeof(pixel_xy));
      // No edge tests: the last row and column are always used, so a region pixel is never on
      // them, and its missing neighbours read used states: the row above row 0 is the used front
      // row, and left of column 0 lies the previous row's used last column.
      uint32_t mask = lsdNeighbourMask(state, p, w);
      while (mask != 0) {
        const int bit = __builtin_ctz(mask);
        mask &= mask - 1;
        const int q = p + neighbour_offset[bit];
        if (dir_x[q] * sum_x + dir_y[q] * sum_y < bound) continue;
        state[q] = kUsed;
        region[size] = q;
        // x + dx >= 0 (column -1 is never free), so the packed add never borrows from y.
        const uint32_t q_xy = pixel_xy + neighbour_step[bit];
        std::memcpy(&region_xy[size], &q_xy, sizeof(q_xy));
        ++size;
        sum_x += dir_x[q];
        sum_y += dir_y[q];
        bound = cos_tau * std::sqrt(sum_x * sum_x + sum_y * sum_y);
      }
    }
    if (size < 4) continue;
    if (regionToSegment(size, min_length, &out[count])) ++count;
  }
  return count;
}

void LineSegmentDetector::regionBox(int size, int* x_min, int* x_max, int* y_min, int* y_max) const {
  // (x, y) pairs are interleaved int16 lanes: 4 pixels a step from lanes that start as pixel 0
  // (which changes no extreme), the rest one by one.
  const int16_t* xy = &region_xy_[0].x;
  int32_t first;
  std::memcpy(&first, xy, sizeof(first));
  cv::v_int16x8 lo = cv::v_reinterpret_as_s16(cv::v_setall_s32(first)), hi = lo;
  int i = 0;
  for (; i + 4 <= size; i += 4) {
    const cv::v_int16x8 v = cv::v_load(xy + 2 * i);
    lo = cv::v_min(lo, v);
    hi = cv::v_max(hi, v);
  }
  int16_t lo_lanes[8], hi_lanes[8];
  cv::v_store(lo_lanes, lo);
  cv::v_store(hi_lanes, hi);
  int x0 = lo_lanes[0], x1 = hi_lanes[0], y0 = lo_lanes[1], y1 = hi_lanes[1];
  for (int lane = 2; lane < 8; lane += 2) {
    x0 = std::min<int>(x0, lo_lanes[lane]);
    x1 = std::max<int>(x1, hi_lanes[lane]);
    y0 = std::min<int>(y0, lo_lanes[lane + 1]);
    y1 = std::max<int>(y1, hi_lanes[lane + 1]);
  }
  for (; i < size; ++i) {
    x0 = std::min<int>(x0, region_xy_[i].x);
    x1 = std::max<int>(x1, region_xy_[i].x);
    y0 = std::min<int>(y0, region_xy_[i].y);
    y1 = std::max<int>(y1, region_xy_[i].y);
  }
  *x_min = x0;
  *x_max = x1;
  *y_min = y0;
  *y_max = y1;
}

bool LineSegmentDetector::regionToSegment(int size, float min_length, DetectedSegment* segment) const {
  // An 8-connected region of `size` pixels spans at most (size - 1) * sqrt(2) along any axis:
  // too small to reach min_length means the length test below would fail anyway.
  if ((size - 1) * 1.5 + 1 < min_length) return false;
  // Its extent along any unit vector is at most the diagonal of its bounding box, so a box whose
  // diagonal + 1 is below min_length fails the length test below too (same result, found with
  // integer passes instead of three passes of double sums; most regions end here on fr1/rpy).
  int x_min, x_max, y_min, y_max;
  regionBox(size, &x_min, &x_max, &y_min, &y_max);
  const double box_dx = x_max - x_min, box_dy = y_max - y_min;
  const double box_length = std::sqrt(box_dx * box_dx + box_dy * box_dy) + 1.0 + 1e-6;  // margin: rounding
  if (box_length < min_length) return false;
  // The same bound fails the thickness test below before the fit (~7 % of the fits on fr1/rpy):
  // more than max_thickness_px pixels per unit of box_length >= length.
  if (size > options_.max_thickness_px * box_length) return false;
  double sw = 0, cx = 0, cy = 0, gx = 0, gy = 0;
  for (int i = 0; i < size; ++i) {
    const int p = region_[i];
    const double m = magnitude_[p];
    sw += m;
    cx += m * region_xy_[i].x;
    cy += m * region_xy_[i].y;
    gx += m * dir_x_[p];
    gy += m * dir_y_[p];
  }
  cx /= sw;
  cy /= sw;
  double sxx = 0, syy = 0, sxy = 0;
  for (int i = 0; i < size; ++i) {
    const int p = region_[i];
    const double m = magnitude_[p], dx = region_xy_[i].x - cx, dy = region_xy_[i].y - cy;
    sxx += m * dx * dx;
    syy += m * dy * dy;
    sxy += m * dx * dy;
  }
  // Principal axis of the weighted scatter = the segment direction.
  const double theta = 0.5 * std::atan2(2 * sxy, sxx - syy);
  double ux = std::cos(theta), uy = std::sin(theta);
  // Convention: the mean gradient points to the left of the direction (y down): flip if needed.
  if (ux * gy - uy * gx > 0) {
    ux = -ux;
    uy = -uy;
  }
  double l_min = 1e30, l_max = -1e30, across2 = 0;
  for (int i = 0; i < size; ++i) {
    const int p = region_[i];
    const double dx = region_xy_[i].x - cx, dy = region_xy_[i].y - cy;
    const double along = dx * ux + dy * uy, across = -dx * uy + dy * ux;
    l_min = std::min(l_min, along);
    l_max = std::max(l_max, along);
    across2 += magnitude_[p] * across * across;
  }
  const double across_rms = std::sqrt(across2 / sw);
  const double length = l_max - l_min + 1;
  // Straight and thin: the weighted RMS distance across the axis (curved or blob-like regions
  // spread out) and the mean thickness (region pixels per unit length).
  if (length < min_length || across_rms > options_.max_rms_width_px || size > options_.max_thickness_px * length) {
    return false;
  }
  // The 2x2 gradient of pixel (x, y) sits at (x + 0.5, y + 0.5).
  const double ox = cx + 0.5, oy = cy + 0.5;
  segment->x0 = static_cast<float>(ox + l_min * ux);
  segment->y0 = static_cast<float>(oy + l_min * uy);
  segment->x1 = static_cast<float>(ox + l_max * ux);
  segment->y1 = static_cast<float>(oy + l_max * uy);
  segment->length = static_cast<float>(l_max - l_min);
  segment->mean_gradient = static_cast<float>(sw / size);
  return true;
}

}  // namespace plumb

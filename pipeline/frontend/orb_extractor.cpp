#include "pipeline/frontend/orb_extractor.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace plumb {
namespace {

// FAST corners kept per level after suppression; a 640x480 level rarely exceeds ~15k at
// threshold 7, and a full buffer only drops corners at the bottom of the image.
constexpr int kMaxCornersPerLevel = 40000;

}  // namespace

OrbExtractor::OrbExtractor(const PinholeCamera& camera, const ExtractorOptions& options)
    : camera_(camera), options_(options),
      pyramid_(camera.width, camera.height, options.num_levels, options.scale_factor),
      fast_(camera.width, camera.height, kMaxCornersPerLevel),
      describer_(pyramid_.stride()) {
  ranked_.resize(kMaxCornersPerLevel);
  by_rank_.resize(kMaxCornersPerLevel);
  rank_start_.resize(kMaxCornersPerLevel + 1);
  cell_has_corner_.resize(static_cast<size_t>(camera.width / 8 + 1) * (camera.height / 8 + 1));
  cell_start_.resize(cell_has_corner_.size() + 1);
  // One bit per column and a spare word per band of rows (see blurAroundKeypoints), and a
  // band's spans.
  CV_Assert(describer_.sampleReach() < OrbDescriber::kBorder);
  buildBandMasks();
  blur_band_words_ = (camera.width + 63) / 64 + 1;
  // + bands_per_keypoint_: a keypoint's last bands may be past the level's last one (ORed with 0).
  blur_band_bits_.resize(static_cast<size_t>(blur_band_words_) *
                         ((camera.height + kBlurBand - 1) / kBlurBand + bands_per_keypoint_));
  blur_spans_.resize(camera.width / 2 + 1);
  // Geometric share per level: n0 * (1/s)^i, summing to num_features (ORB-SLAM's split).
  const int levels = pyramid_.numLevels();
  const double inv = 1.0 / options.scale_factor;
  const double n0 = options.num_features * (1 - inv) / (1 - std::pow(inv, levels));
  int assigned = 0;
  for (int i = 0; i < levels - 1; ++i) {
    features_per_level_[i] = static_cast<int>(std::lround(n0 * std::pow(inv, i)));
    assigned += features_per_level_[i];
  }
  features_per_level_[levels - 1] = std::max(0, options.num_features - assigned);
}

void OrbExtractor::extract(const cv::Mat& grey, FrameFeatures& out) {
  const auto t0 = std::chrono::steady_clock::now();
  pyramid_.buildLevels(grey);  // each level's blur comes in selectOnLevel, where BRIEF reads it
  pyramid_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  int carry = 0;  // features a level could not provide move to the next one
  const int max_total = std::min<int>(options_.num_features, kMaxKeypoints);
  for (int level = 0; level < pyramid_.numLevels(); ++level) {
    const int before = static_cast<int>(out.keypoints.size());
    const int wanted = std::min(features_per_level_[level] + carry, max_total - before);
    if (wanted <= 0) break;
    selectOnLevel(level, wanted, out);
    carry = wanted - (static_cast<int>(out.keypoints.size()) - before);
  }
}

void OrbExtractor::selectOnLevel(int level, int wanted, FrameFeatures& out) {
  const cv::Mat& image = pyramid_.level(level);
  const int border = OrbDescriber::kBorder;
  const int cell = std::max(8, options_.cell_size_px);
  const int cols = std::max(1, (image.cols - 2 * border + cell - 1) / cell);
  const int rows = std::max(1, (image.rows - 2 * border + cell - 1) / cell);
  // Adaptive threshold (ORB-SLAM): the whole level at the high threshold, then only the cells
  // that found nothing again at the low one. Scanning everything at the low threshold would
  // score ~10x more corners on noisy Kinect images.
  fast_.begin(image, border);
  fast_.scan(options_.fast_threshold_high, 0, 0, image.cols, image.rows);
  std::fill_n(cell_has_corner_.begin(), cols * rows, false);
  for (int i = 0; i < fast_.numRaw(); ++i) {
    const FastCorner& c = fast_.rawCorners()[i];
    cell_has_corner_[((c.y - border) / cell) * cols + (c.x - border) / cell] = true;
  }
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols;) {  // runs of neighbouring empty cells in one call (the same pixels)
      if (cell_has_corner_[r * cols + c]) {
        ++c;
        continue;
      }
      const int run_start = c;
      while (c < cols && !cell_has_corner_[r * cols + c]) ++c;
      const int x0 = border + run_start * cell, y0 = border + r * cell;
      fast_.scan(options_.fast_threshold_low, x0, y0, border + c * cell, y0 + cell);
    }
  }
  const int num = fast_.suppress();

  // Round-robin over cells = order by (rank within its cell, strength), where strength is the
  // score with a raster-order tie-break (a total order: the result is unique). Counting sorts by
  // cell and then by rank, so only the small per-cell and per-rank groups need comparisons.
  const FastCorner* corners = fast_.corners();
  const int num_cells = cols * rows;
  int* cell_start = cell_start_.data();
  std::fill_n(cell_start, num_cells + 1, 0);
  for (int i = 0; i < num; ++i) {
    const int c = ((corners[i].y - border) / cell) * cols + (corners[i].x - border) / cell;
    by_rank_[i].cell = c;
    ++cell_start[c + 1];
  }
  for (int c = 0; c < num_cells; ++c) cell_start[c + 1] += cell_start[c];
  for (int i = 0; i < num; ++i) {
    RankedCorner& r = ranked_[cell_start[by_rank_[i].cell]++];
    r.corner = corners[i];
    r.cell = by_rank_[i].cell;
  }
  auto stronger = [](const RankedCorner& a, const RankedCorner& b) {
    if (a.corner.score != b.corner.score) return a.corner.score > b.corner.score;
    return a.corner.y != b.corner.y ? a.corner.y < b.corner.y : a.corner.x < b.corner.x;  // deterministic tie-break
  };
  int* rank_start = rank_start_.data();
  int max_rank = 0;
  for (int c = 0, first = 0; c < num_cells; ++c) {  // cell_start[c] is now the end of cell c
    const int end = cell_start[c];
    std::sort(ranked_.begin() + first, ranked_.begin() + end, stronger);
    for (int i = first; i < end; ++i) ranked_[i].rank = i - first;
    max_rank = std::max(max_rank, end - first);
    first = end;
  }
  std::fill_n(rank_start, max_rank + 1, 0);
  for (int i = 0; i < num; ++i) ++rank_start[ranked_[i].rank + 1];
  for (int r = 0; r < max_rank; ++r) rank_start[r + 1] += rank_start[r];
  for (int i = 0; i < num; ++i) by_rank_[rank_start[ranked_[i].rank]++] = ranked_[i];
  const int take = std::min(wanted, num);
  for (int r = 0, first = 0; first < take; ++r) {  // rank_start[r] is now the end of rank r
    const int end = rank_start[r];
    if (end <= take) {
      std::sort(by_rank_.begin() + first, by_rank_.begin() + end, stronger);
    } else {
      std::partial_sort(by_rank_.begin() + first, by_rank_.begin() + take, by_rank_.begin() + end, stronger);
    }
    first = end;
  }

  // Orientation from the level image first, then the blur of just the rows and columns the
  // descriptors of these keypoints read (their orientation bins known), then rotated BRIEF.
  const float scale = pyramid_.scale(level);
  const uint8_t* level_origin = image.ptr<uint8_t>(0);
  const int stride = pyramid_.stride();
  const int first = static_cast<int>(out.keypoints.size());
  int kept = 0;
  for (; kept < take; ++kept) {
    const FastCorner& c = by_rank_[kept].corner;
    KeypointObservation* kp = out.keypoints.emplace_back();
    Descriptor256* descriptor = out.keypoint_descriptors.emplace_back();
    if (kp == nullptr || descriptor == nullptr) {  // capacity reached: keep the arrays parallel
      if (kp != nullptr) out.keypoints.pop_back();
      if (descriptor != nullptr) out.keypoint_descriptors.pop_back();
      break;
    }
    if (kept + 1 < take) {
      // The patches of consecutive keypoints are far apart (ranked order) and the level was
      // written long ago: fetch the next keypoint's rows while this one is computed.
      const FastCorner& next = by_rank_[kept + 1].corner;
      const uint8_t* next_patch = level_origin + next.y * stride + next.x;
      for (int dy = -OrbDescriber::kPatchRadius; dy <= OrbDescriber::kPatchRadius; ++dy) {
        __builtin_prefetch(next_patch + dy * stride - OrbDescriber::kPatchRadius);
        __builtin_prefetch(next_patch + dy * stride + OrbDescriber::kPatchRadius);
      }
    }
    kp->angle_deg = describer_.orientationDeg(level_origin + c.y * stride + c.x);
    kp->px = Eigen::Vector2f(c.x * scale, c.y * scale);
    kp->px_undist = camera_.undistortPoint(kp->px.x(), kp->px.y()).cast<float>();
    kp->response = c.score;
    kp->octave = static_cast<int8_t>(level);
  }

  blurAroundKeypoints(level, out.keypoints.data() + first, kept);

  const uint8_t* blurred_origin = pyramid_.blurred(level).ptr<uint8_t>(0);
  for (int i = 0; i < kept; ++i) {
    const FastCorner& c = by_rank_[i].corner;
    describer_.describe(blurred_origin + c.y * stride + c.x, out.keypoints[first + i].angle_deg,
                        out.keypoint_descriptors[first + i]);
  }
}

void OrbExtractor::blurAroundKeypoints(int level, const KeypointObservation* keypoints, int count) {
  // Bands of kBlurBand rows, one bit per column: the columns each keypoint's tests read on the
  // band's rows (OrbDescriber::sampleRowMask of its orientation bin, ORed over the rows of the
  // band; see buildBandMasks), placed at x - reach: bits of two words. Then each band is blurred
  // on the runs of set bits, a run widened to kMinBlurSpan (one vector block in both passes) and
  // runs less than kBlurSpanGap apart joined, since a separate run costs its own vertical margin
  // and set-up.
  const cv::Mat& image = pyramid_.level(level);
  const int words = blur_band_words_;
  const int num_bands = (image.rows + kBlurBand - 1) / kBlurBand;
  uint64_t* bits = blur_band_bits_.data();
  std::fill_n(bits, static_cast<size_t>(num_bands) * words, 0);
  const int reach = describer_.sampleReach();  // < kBorder: every mask lies inside the level
  for (int i = 0; i < count; ++i) {
    const FastCorner& c = by_rank_[i].corner;
    const int top = c.y - reach, base = c.x - reach, shift = base & 63;
    const uint64_t* masks = bandMasks(OrbDescriber::angleBin(keypoints[i].angle_deg), top % kBlurBand);
    uint64_t* band = bits + static_cast<size_t>(top / kBlurBand) * words + (base >> 6);
    for (int j = 0; j < bands_per_keypoint_; ++j, band += words) {
      band[0] |= masks[j] << shift;
      band[1] |= (masks[j] >> 1) >> (63 - shift);  // the bits shifted past word 0 (none when shift is 0)
    }
  }
  ImagePyramid::Span* spans = blur_spans_.data();
  for (int b = 0; b < num_bands; ++b) {
    // Runs from the edges of the bit row (bits that differ from the one before); the spare last
    // word is never set, so every run ends inside the row.
    const uint64_t* row = bits + static_cast<size_t>(b) * words;
    int num_spans = 0, run_start = -1;
    uint64_t previous_top_bit = 0;
    for (int w = 0; w < words; ++w) {
      const uint64_t word = row[w];
      uint64_t edges = word ^ ((word << 1) | previous_top_bit);
      previous_top_bit = word >> 63;
      for (; edges != 0; edges &= edges - 1) {
        const int x = w * 64 + __builtin_ctzll(edges);
        if (run_start < 0) {
          run_start = x;
          continue;
        }
        ImagePyramid::Span span{run_start, std::min(std::max(x, run_start + kMinBlurSpan), image.cols)};
        span.x0 = std::max(0, std::min(span.x0, span.x1 - kMinBlurSpan));
        run_start = -1;
        if (num_spans > 0 && span.x0 <= spans[num_spans - 1].x1 + kBlurSpanGap) {
          spans[num_spans - 1].x1 = std::max(spans[num_spans - 1].x1, span.x1);
        } else {
          spans[num_spans++] = span;
        }
      }
    }
    if (num_spans > 0) pyramid_.blurRowSpans(level, b * kBlurBand, std::min((b + 1) * kBlurBand, image.rows), spans, num_spans);
  }
}

void OrbExtractor::buildBandMasks() {
  // Keypoint rows top .. top + 2 * reach; with phase = top % kBlurBand, row offset o falls in
  // band (phase + o) / kBlurBand of the keypoint's bands.
  const int reach = describer_.sampleReach();
  bands_per_keypoint_ = (kBlurBand - 1 + 2 * reach) / kBlurBand + 1;
  band_masks_.assign(static_cast<size_t>(OrbDescriber::kAngleBins) * kBlurBand * bands_per_keypoint_, 0);
  for (int bin = 0; bin < OrbDescriber::kAngleBins; ++bin) {
    for (int phase = 0; phase < kBlurBand; ++phase) {
      uint64_t* masks = band_masks_.data() + (static_cast<size_t>(bin) * kBlurBand + phase) * bands_per_keypoint_;
      for (int o = 0; o <= 2 * reach; ++o) masks[(phase + o) / kBlurBand] |= describer_.sampleRowMask(bin, o - reach);
    }
  }
}

}  // namespace plumb

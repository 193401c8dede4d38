// The vectorised front-end kernels against plain scalar oracles written from their definitions:
// the pyramid (bilinear 1.2 steps, then the 7-tap fixed-point blur), the intensity-centroid
// orientation and the LBD-style line descriptor. The fast versions claim to compute exactly the
// same integers and floats, so the comparisons are for equality, not tolerance.
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "pipeline/frontend/frame_features.h"
#include "pipeline/frontend/image_pyramid.h"
#include "pipeline/frontend/line_descriptor.h"
#include "pipeline/frontend/orb_descriptor.h"

namespace plumb {
namespace {

// A textured test image: smoothed noise plus a few strong edges, odd width so row tails
// (widths not a multiple of 8 or 16) are exercised on every level.
cv::Mat testImage(int width, int height, uint64_t seed) {
  cv::Mat img(height, width, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(img, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(img, img, cv::Size(5, 5), 1.0);
  cv::rectangle(img, cv::Rect(width / 5, height / 4, width / 3, height / 3), cv::Scalar(250), cv::FILLED);
  cv::line(img, cv::Point(0, height - 1), cv::Point(width - 1, 0), cv::Scalar(5), 3);
  return img;
}

// One axis of bilinear resampling with pixel centres at +0.5 (cv::resize's convention), in
// 1/2048: source index and weight of index + 1.
void bilinearTaps(int src_size, int dst_size, std::vector<int>* index, std::vector<int>* weight) {
  const double step = static_cast<double>(src_size) / dst_size;
  for (int d = 0; d < dst_size; ++d) {
    const double f = (d + 0.5) * step - 0.5;
    int i = static_cast<int>(std::floor(f));
    double fraction = f - i;
    if (i < 0) i = 0, fraction = 0;
    if (i >= src_size - 1) i = src_size - 1, fraction = 0;
    index->push_back(i);
    weight->push_back(static_cast<int>(std::lround(fraction * 2048)));
  }
}

// Exact bilinear: sum of the four products, rounded once.
cv::Mat referenceDownsample(const cv::Mat& src, cv::Size size) {
  std::vector<int> xi, xw, yi, yw;
  bilinearTaps(src.cols, size.width, &xi, &xw);
  bilinearTaps(src.rows, size.height, &yi, &yw);
  cv::Mat dst(size, CV_8UC1);
  for (int y = 0; y < size.height; ++y) {
    const int y1 = std::min(yi[y] + 1, src.rows - 1);
    for (int x = 0; x < size.width; ++x) {
      const int x1 = std::min(xi[x] + 1, src.cols - 1);
      const long sum = static_cast<long>(src.at<uint8_t>(yi[y], xi[x])) * (2048 - xw[x]) * (2048 - yw[y]) +
                       static_cast<long>(src.at<uint8_t>(yi[y], x1)) * xw[x] * (2048 - yw[y]) +
                       static_cast<long>(src.at<uint8_t>(y1, xi[x])) * (2048 - xw[x]) * yw[y] +
                       static_cast<long>(src.at<uint8_t>(y1, x1)) * xw[x] * yw[y];
      dst.at<uint8_t>(y, x) = static_cast<uint8_t>((sum + (1L << 21)) >> 22);
    }
  }
  return dst;
}

// 7-tap Gaussian (sigma 2) in 8.8 fixed point, vertical then horizontal, each pass rounded,
// reflected borders (BORDER_REFLECT_101).
cv::Mat referenceBlur(const cv::Mat& src) {
  const cv::Mat g = cv::getGaussianKernel(7, 2.0, CV_64F);
  int k[7], sum = 0;
  for (int i = 0; i < 7; ++i) sum += k[i] = static_cast<int>(std::lround(g.at<double>(i) * 256));
  k[3] += 256 - sum;
  auto reflect = [](int i, int n) { return i < 0 ? -i : (i >= n ? 2 * n - 2 - i : i); };
  cv::Mat vertical(src.size(), CV_32SC1), dst(src.size(), CV_8UC1);
  for (int y = 0; y < src.rows; ++y)
    for (int x = 0; x < src.cols; ++x) {
      int acc = 0;
      for (int i = 0; i < 7; ++i) acc += k[i] * src.at<uint8_t>(reflect(y + i - 3, src.rows), x);
      vertical.at<int>(y, x) = (acc + 128) >> 8;
    }
  for (int y = 0; y < src.rows; ++y)
    for (int x = 0; x < src.cols; ++x) {
      int acc = 0;
      for (int i = 0; i < 7; ++i) acc += k[i] * vertical.at<int>(y, reflect(x + i - 3, src.cols));
      dst.at<uint8_t>(y, x) = static_cast<uint8_t>((acc + 128) >> 8);
    }
  return dst;
}

TEST(FrontendKernels, PyramidEqualsExactBilinearAndFixedPointBlur) {
  const cv::Mat img = testImage(643, 481, 11);
  ImagePyramid pyramid(img.cols, img.rows, 8, 1.2f);
  pyramid.build(img);
  ASSERT_EQ(cv::norm(pyramid.level(0), img, cv::NORM_INF), 0);
  for (int i = 0; i < pyramid.numLevels(); ++i) {
    if (i > 0) {
      const cv::Mat expected = referenceDownsample(pyramid.level(i - 1), pyramid.level(i).size());
      EXPECT_EQ(cv::norm(pyramid.level(i), expected, cv::NORM_INF), 0) << "level " << i;
    }
    EXPECT_EQ(cv::norm(pyramid.blurred(i), referenceBlur(pyramid.level(i)), cv::NORM_INF), 0) << "blur, level " << i;
  }
  // The blur is not the identity and the levels really shrink (the test can fail).
  EXPECT_GT(cv::norm(pyramid.blurred(0), pyramid.level(0), cv::NORM_INF), 20);
  EXPECT_EQ(pyramid.level(7).cols, static_cast<int>(std::lround(643 / std::pow(1.2f, 7.f))));
}

TEST(FrontendKernels, PyramidEqualsExactBilinearWithAndWithoutShuffleGather) {
  // Scale 1.2 (the default) and 1.5 take the byte-shuffle gather on x86-64 with SSSE3 and on
  // aarch64; 2.5 spreads 4 outputs over more than 8 source pixels and takes the portable path.
  const cv::Mat img = testImage(517, 389, 14);
  for (const float scale : {1.2f, 1.5f, 2.5f}) {
    ImagePyramid pyramid(img.cols, img.rows, 4, scale);
    pyramid.buildLevels(img);
    for (int i = 1; i < pyramid.numLevels(); ++i) {
      EXPECT_EQ(pyramid.shuffleGatherPossible(i), scale < 2.0f) << "scale " << scale << " level " << i;
      const cv::Mat expected = referenceDownsample(pyramid.level(i - 1), pyramid.level(i).size());
      EXPECT_EQ(cv::norm(pyramid.level(i), expected, cv::NORM_INF), 0) << "scale " << scale << " level " << i;
    }
  }
}

TEST(FrontendKernels, BlurPathsEqualTheFixedPointReference) {
  // The byte multiply-add blur (SSSE3, where the CPU has it) and the portable 16-bit one give the
  // reference's integers on every level, including the 8..15 and < 8 px wide levels and edges.
  const cv::Mat img = testImage(643, 481, 15);
  ImagePyramid portable(img.cols, img.rows, 8, 1.2f), bytes(img.cols, img.rows, 8, 1.2f);
  ASSERT_TRUE(portable.setBlurPath(ImagePyramid::BlurPath::kPortable));
  EXPECT_EQ(portable.blurPath(), ImagePyramid::BlurPath::kPortable);
  const bool have_bytes = bytes.setBlurPath(ImagePyramid::BlurPath::kByteMultiplyAdd);
  portable.build(img);
  bytes.build(img);
  for (int i = 0; i < 8; ++i) {
    const cv::Mat expected = referenceBlur(portable.level(i));
    EXPECT_EQ(cv::norm(portable.blurred(i), expected, cv::NORM_INF), 0) << "portable, level " << i;
    if (have_bytes) {
      EXPECT_EQ(cv::norm(bytes.blurred(i), expected, cv::NORM_INF), 0) << "bytes, level " << i;
    }
  }
  // Narrow images take the 8-wide blocks (8..15 px) and the scalar columns (< 8 px).
  for (const int width : {5, 8, 11, 16, 21}) {
    const cv::Mat narrow = testImage(width, 40, 16 + width);
    ImagePyramid a(width, 40, 1, 1.2f), b(width, 40, 1, 1.2f);
    ASSERT_TRUE(a.setBlurPath(ImagePyramid::BlurPath::kPortable));
    ASSERT_EQ(b.setBlurPath(ImagePyramid::BlurPath::kByteMultiplyAdd), have_bytes);
    a.build(narrow);
    b.build(narrow);
    const cv::Mat expected = referenceBlur(narrow);
    EXPECT_EQ(cv::norm(a.blurred(0), expected, cv::NORM_INF), 0) << "portable, width " << width;
    if (have_bytes) {
      EXPECT_EQ(cv::norm(b.blurred(0), expected, cv::NORM_INF), 0) << "bytes, width " << width;
    }
  }
  if (!have_bytes) GTEST_SKIP() << "no SSSE3 (or not x86-64): only the portable blur was checked";
}

class BlurOfRectangles : public ::testing::TestWithParam<ImagePyramid::BlurPath> {
 protected:
  // whole_: a 643x481 test image's pyramid blurred everywhere; parts_: its levels only, on the
  // blur path under test. False when this CPU or build does not have the path.
  bool makePyramids(uint64_t seed) {
    const cv::Mat img = testImage(643, 481, seed);
    whole_ = std::make_unique<ImagePyramid>(img.cols, img.rows, 8, 1.2f);
    whole_->build(img);
    parts_ = std::make_unique<ImagePyramid>(img.cols, img.rows, 8, 1.2f);
    if (!parts_->setBlurPath(GetParam())) return false;
    parts_->buildLevels(img);
    return true;
  }
  std::unique_ptr<ImagePyramid> whole_, parts_;
};

TEST_P(BlurOfRectangles, EqualTheWholeImageBlurInsideThem) {
  // ORB blurs only around its keypoints (ImagePyramid::blurRect): small, odd-sized rectangles
  // at the image edges and inside must get exactly the whole-image values, and nothing outside
  // them may be written.
  if (!makePyramids(13)) GTEST_SKIP() << "this blur path does not exist on this CPU";
  const ImagePyramid& whole = *whole_;
  ImagePyramid& parts = *parts_;
  const cv::Rect rects[] = {{0, 0, 5, 3}, {0, 0, 16, 16}, {1, 2, 7, 9}, {30, 40, 17, 33}, {100, 7, 64, 16},
                            {200, 200, 3, 40}, {600, 450, 43, 31}, {630, 10, 13, 20}, {2, 470, 30, 11}};
  for (int level = 0; level < 8; ++level) {
    const cv::Mat before = parts.blurred(level).clone();
    cv::Mat written(before.size(), CV_8UC1, cv::Scalar(0));
    for (const cv::Rect& r : rects) {
      const cv::Rect clipped = r & cv::Rect(0, 0, before.cols, before.rows);
      if (clipped.empty()) continue;
      parts.blurRect(level, r.x, r.y, r.x + r.width, r.y + r.height);
      written(clipped).setTo(1);
      EXPECT_EQ(cv::norm(parts.blurred(level)(clipped), whole.blurred(level)(clipped), cv::NORM_INF), 0)
          << "level " << level << " rect " << r;
    }
    const cv::Mat untouched = written == 0;
    EXPECT_EQ(cv::norm(parts.blurred(level), before, cv::NORM_INF, untouched), 0) << "level " << level;
    EXPECT_GT(cv::countNonZero(written), 0);
  }
}

TEST_P(BlurOfRectangles, RowSpansEqualTheWholeImageBlurInsideThem) {
  // blurRowSpans (ORB's per-band blur): bands of 1 to 9 rows, each with up to 6 random spans of
  // 1 to 70 columns, overlapping or not, at the edges and inside, on every level.
  if (!makePyramids(17)) GTEST_SKIP() << "this blur path does not exist on this CPU";
  const ImagePyramid& whole = *whole_;
  ImagePyramid& parts = *parts_;
  cv::RNG rng(5);
  int spans_checked = 0;
  for (int level = 0; level < 8; ++level) {
    const cv::Mat before = parts.blurred(level).clone();
    const int w = before.cols, h = before.rows;
    cv::Mat written(before.size(), CV_8UC1, cv::Scalar(0));
    for (int band = 0; band < 40; ++band) {
      const int y0 = band == 0 ? 0 : (band == 1 ? h - 3 : rng.uniform(0, h));
      const int y1 = std::min(h, y0 + rng.uniform(1, 10));
      ImagePyramid::Span spans[6];
      const int num_spans = rng.uniform(1, 7);
      for (int i = 0; i < num_spans; ++i) {
        const int width = std::min(w, rng.uniform(1, 71));
        const int x0 = i == 0 && band % 3 == 0 ? 0 : (i == 1 && band % 3 == 1 ? w - width : rng.uniform(0, w - width + 1));
        spans[i] = {x0, x0 + width};
        written(cv::Rect(x0, y0, width, y1 - y0)).setTo(1);
      }
      parts.blurRowSpans(level, y0, y1, spans, num_spans);
      for (int i = 0; i < num_spans; ++i) {
        const cv::Rect r(spans[i].x0, y0, spans[i].x1 - spans[i].x0, y1 - y0);
        ASSERT_EQ(cv::norm(parts.blurred(level)(r), whole.blurred(level)(r), cv::NORM_INF), 0)
            << "level " << level << " span " << r;
        ++spans_checked;
      }
    }
    const cv::Mat untouched = written == 0;
    EXPECT_EQ(cv::norm(parts.blurred(level), before, cv::NORM_INF, untouched), 0) << "level " << level;
  }
  EXPECT_GT(spans_checked, 500);
}

INSTANTIATE_TEST_SUITE_P(FrontendKernels, BlurOfRectangles,
                         ::testing::Values(ImagePyramid::BlurPath::kPortable, ImagePyramid::BlurPath::kByteMultiplyAdd),
                         [](const ::testing::TestParamInfo<ImagePyramid::BlurPath>& info) {
                           return info.param == ImagePyramid::BlurPath::kPortable ? "Portable" : "ByteMultiplyAdd";
                         });

// Images for the orientation test: smoothed texture, raw uniform noise, and 0/255 halves split
// left-right and top-bottom (the largest |m10| and |m01| the disc can have, where a 16-bit
// partial sum would wrap first), plus a 0/255 checkerboard of 1 px.
std::vector<cv::Mat> orientationTestImages() {
  std::vector<cv::Mat> images{testImage(200, 150, 12)};
  cv::Mat noise(120, 161, CV_8UC1);
  cv::RNG(7).fill(noise, cv::RNG::UNIFORM, 0, 256);
  images.push_back(noise);
  for (int split = 0; split < 3; ++split) {
    cv::Mat img(90, 97, CV_8UC1);
    for (int y = 0; y < img.rows; ++y)
      for (int x = 0; x < img.cols; ++x) {
        const bool bright = split == 0 ? x >= img.cols / 2 : split == 1 ? y >= img.rows / 2 : (x + y) % 2 == 0;
        img.at<uint8_t>(y, x) = bright ? 255 : 0;
      }
    images.push_back(img);
    images.push_back(255 - img);
  }
  return images;
}

TEST(FrontendKernels, OrientationEqualsIntensityCentroidOverTheDisc) {
  const int r = OrbDescriber::kPatchRadius;
  // Every path this CPU and build have (the x86 one needs x86-64 with SSSE3; elsewhere the
  // portable path alone is checked).
  std::vector<OrbDescriber::KernelPath> paths{OrbDescriber::KernelPath::kPortable};
  if (OrbDescriber(64).setKernelPath(OrbDescriber::KernelPath::kX86)) paths.push_back(OrbDescriber::KernelPath::kX86);
  for (const auto path : paths) {
    SCOPED_TRACE(path == OrbDescriber::KernelPath::kPortable ? "portable" : "x86");
    int compared = 0, image_index = 0;
    std::array<int, 4> quadrants{};
    for (const cv::Mat& img : orientationTestImages()) {
      SCOPED_TRACE("image " + std::to_string(image_index++));
      OrbDescriber describer(static_cast<int>(img.step[0]));
      ASSERT_TRUE(describer.setKernelPath(path));
      for (int y = OrbDescriber::kBorder; y < img.rows - OrbDescriber::kBorder; y += 3) {
        for (int x = OrbDescriber::kBorder; x < img.cols - OrbDescriber::kBorder; x += 5) {
          int m10 = 0, m01 = 0;
          for (int dy = -r; dy <= r; ++dy) {
            const int w = static_cast<int>(std::floor(std::sqrt(double(r * r - dy * dy)) + 0.5));
            for (int dx = -w; dx <= w; ++dx) {
              m10 += dx * img.at<uint8_t>(y + dy, x + dx);
              m01 += dy * img.at<uint8_t>(y + dy, x + dx);
            }
          }
          const float expected = cv::fastAtan2(static_cast<float>(m01), static_cast<float>(m10));
          ASSERT_EQ(describer.orientationDeg(img.ptr<uint8_t>(y) + x), expected) << "at " << x << "," << y;
          ++quadrants[std::min(3, static_cast<int>(expected / 90))];
          ++compared;
        }
      }
    }
    EXPECT_GT(compared, 1500);
    for (int q : quadrants) EXPECT_GT(q, 10);  // every direction occurs
  }
}

// The x86 path's bit packing (cmp + adc) against the portable compares, every orientation bin,
// on raw noise (many equal pairs: the strict < matters) and the smoothed test image; and the
// bins really differ (the angle picks the pattern).
TEST(FrontendKernels, DescriptorPathsGiveTheSameBits) {
  std::vector<cv::Mat> images = orientationTestImages();
  cv::Mat coarse_noise(70, 83, CV_8UC1);
  cv::RNG(3).fill(coarse_noise, cv::RNG::UNIFORM, 0, 4);  // values 0..3: many ties
  images.push_back(coarse_noise);
  int compared = 0, differing_bins = 0;
  for (const cv::Mat& img : images) {
    OrbDescriber portable(static_cast<int>(img.step[0])), x86(static_cast<int>(img.step[0]));
    ASSERT_TRUE(portable.setKernelPath(OrbDescriber::KernelPath::kPortable));
    if (!x86.setKernelPath(OrbDescriber::KernelPath::kX86)) GTEST_SKIP() << "no SSSE3 (or not x86-64)";
    for (int y = OrbDescriber::kBorder; y < img.rows - OrbDescriber::kBorder; y += 7) {
      for (int x = OrbDescriber::kBorder; x < img.cols - OrbDescriber::kBorder; x += 11) {
        Descriptor256 previous;
        for (int bin = 0; bin < OrbDescriber::kAngleBins; ++bin) {
          const float angle = bin * 360.0f / OrbDescriber::kAngleBins;
          ASSERT_EQ(OrbDescriber::angleBin(angle), bin);
          Descriptor256 a, b;
          portable.describe(img.ptr<uint8_t>(y) + x, angle, a);
          x86.describe(img.ptr<uint8_t>(y) + x, angle, b);
          ASSERT_EQ(a.words, b.words) << "at " << x << "," << y << ", bin " << bin;
          if (bin > 0 && a.words != previous.words) ++differing_bins;
          previous = a;
          ++compared;
        }
      }
    }
  }
  EXPECT_GT(compared, 3000);
  EXPECT_GT(differing_bins, compared / 2);
}

// The descriptor's definition, one sample at a time with plain if/else accumulation.
Descriptor256 referenceLineDescriptor(const cv::Mat& image, cv::Point2f start, cv::Point2f end,
                                      const LineDescriptorOptions& options) {
  constexpr int kBands = 9, kStats = 8;
  float band[kBands][kStats] = {};
  Descriptor256 out;
  const float dx = end.x - start.x, dy = end.y - start.y;
  const float length = std::sqrt(dx * dx + dy * dy);
  const float ux = dx / length, uy = dy / length, nx = -uy, ny = ux;
  const int w = options.band_width, rows = kBands * w, half_rows = rows / 2;
  const int positions = std::clamp(static_cast<int>(length), 4, std::max(4, options.max_positions));
  const float sigma = 0.5f * rows;
  for (int r = 0; r < rows; ++r) {
    const float offset = static_cast<float>(r - half_rows);
    const float weight = std::exp(-0.5f * offset * offset / (sigma * sigma));
    const float step_x = dx / positions, step_y = dy / positions;
    float fx = start.x + 0.5f * step_x + offset * nx + 0.5f, fy = start.y + 0.5f * step_y + offset * ny + 0.5f;
    for (int k = 0; k < positions; ++k, fx += step_x, fy += step_y) {
      if (fx < 1 || fy < 1) continue;
      const int x = static_cast<int>(fx), y = static_cast<int>(fy);
      if (x < 1 || y < 1 || x > image.cols - 2 || y > image.rows - 2) continue;
      const float gx = static_cast<float>(image.at<uint8_t>(y, x + 1) - image.at<uint8_t>(y, x - 1));
      const float gy = static_cast<float>(image.at<uint8_t>(y + 1, x) - image.at<uint8_t>(y - 1, x));
      const float across = weight * (gx * nx + gy * ny), along = weight * (gx * ux + gy * uy);
      float* s = band[r / w] + (2 * k >= positions ? 4 : 0);
      if (across > 0) s[0] += across; else s[1] -= across;
      if (along > 0) s[2] += along; else s[3] -= along;
    }
  }
  int bit = 0;
  auto put = [&](bool value) {
    if (value) out.words[bit >> 6] |= 1ULL << (bit & 63);
    ++bit;
  };
  for (int i = 0; i < kBands; ++i)
    for (int j = i + 1; j < kBands && j - i <= 4; ++j)
      for (int s = 0; s < kStats; ++s) put(band[i][s] > band[j][s]);
  for (int i = 0; i < kBands - 1; ++i) {
    const float* b = band[i];
    put(b[0] > b[1]);
    put(b[4] > b[5]);
    put(b[2] > b[3]);
    put(b[6] > b[7]);
    put(b[0] > b[4]);
    put(b[1] > b[5]);
  }
  return out;
}

TEST(FrontendKernels, LineDescriptorEqualsItsScalarDefinition) {
  const cv::Mat img = testImage(320, 240, 13);
  LineDescriptorOptions options;
  cv::RNG rng(14);
  int distinct = 0;
  Descriptor256 previous;
  for (int i = 0; i < 300; ++i) {
    // The default band width (row weights from a table) and two others (computed per row).
    options.band_width = i % 10 == 8 ? 2 : (i % 10 == 9 ? 4 : 3);
    // Segments of every direction and length, some reaching past the image border.
    const cv::Point2f start(rng.uniform(-10.f, 330.f), rng.uniform(-10.f, 250.f));
    const float angle = rng.uniform(0.f, static_cast<float>(2 * M_PI)), length = rng.uniform(5.f, 120.f);
    const cv::Point2f end(start.x + length * std::cos(angle), start.y + length * std::sin(angle));
    Descriptor256 fast;
    computeLineDescriptor(img, start, end, options, fast);
    const Descriptor256 expected = referenceLineDescriptor(img, start, end, options);
    ASSERT_EQ(fast.words, expected.words) << "segment " << i;
    distinct += hammingDistance(fast, previous) > 0;
    previous = fast;
  }
  EXPECT_GT(distinct, 250);  // the descriptors depend on the segment
}

// hammingDistance (SSE2 bit-slicing on x86-64 without popcnt) against a bit-by-bit count.
TEST(FrontendKernels, HammingDistanceCountsDifferingBits) {
  cv::RNG rng(21);
  auto randomWord = [&rng] { return (uint64_t(uint32_t(rng)) << 32) | uint32_t(rng); };
  for (int i = 0; i < 2000; ++i) {
    Descriptor256 a, b;
    for (int w = 0; w < 4; ++w) {
      a.words[w] = randomWord();
      // Every pattern of agreement: equal words, complements, sparse and dense differences.
      switch (i % 4) {
        case 0: b.words[w] = randomWord(); break;
        case 1: b.words[w] = a.words[w] ^ (uint64_t(1) << (rng.uniform(0, 64))); break;
        case 2: b.words[w] = ~a.words[w]; break;
        default: b.words[w] = w == i % 3 ? a.words[w] : randomWord(); break;
      }
    }
    int expected = 0;
    for (int w = 0; w < 4; ++w)
      for (int bit = 0; bit < 64; ++bit) expected += int(((a.words[w] ^ b.words[w]) >> bit) & 1);
    ASSERT_EQ(hammingDistance(a, b), expected) << "pair " << i;
    ASSERT_EQ(hammingDistance(b, a), expected);
    ASSERT_EQ(hammingDistance(a, a), 0);
  }
  Descriptor256 zero, ones;
  ones.words = {~uint64_t(0), ~uint64_t(0), ~uint64_t(0), ~uint64_t(0)};
  EXPECT_EQ(hammingDistance(zero, ones), 256);
}

}  // namespace
}  // namespace plumb

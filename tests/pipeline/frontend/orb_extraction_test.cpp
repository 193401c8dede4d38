// ORB front end: FAST against a brute-force oracle, keypoint count/geometry on real frames,
// determinism, rotation behaviour of orientation + rotated BRIEF, spread on low texture.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "pipeline/frontend/feature_extractor.h"
#include "pipeline/frontend/image_pyramid.h"
#include "pipeline/frontend/orb_descriptor.h"
#include "pipeline/frontend/orb_extractor.h"
#include "pipeline/frontend/orb_fast.h"
#include "tests/pipeline/frontend_test_support.h"

namespace plumb {
namespace {

// Brute-force FAST-9 score: the largest t for which some arc of 9 is all > t brighter or darker.
int bruteForceScore(const cv::Mat& img, int x, int y) {
  static const int cx[16] = {0, 1, 2, 3, 3, 3, 2, 1, 0, -1, -2, -3, -3, -3, -2, -1};
  static const int cy[16] = {-3, -3, -2, -1, 0, 1, 2, 3, 3, 3, 2, 1, 0, -1, -2, -3};
  const int c = img.at<uint8_t>(y, x);
  int best = 0;
  for (int s = 0; s < 16; ++s) {
    int bright = 1000, dark = 1000;
    for (int k = 0; k < 9; ++k) {
      const int v = img.at<uint8_t>(y + cy[(s + k) % 16], x + cx[(s + k) % 16]);
      bright = std::min(bright, v - c);
      dark = std::min(dark, c - v);
    }
    best = std::max({best, bright, dark});
  }
  return best;
}

TEST(FastDetector, MatchesBruteForceSegmentTestAndScore) {
  cv::Mat img(120, 160, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(img, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(img, img, cv::Size(5, 5), 1.2);
  const int threshold = 10, border = 5;
  FastDetector fast(160, 120, 20000);
  fast.begin(img, border);
  fast.scan(threshold, 0, 0, img.cols, img.rows);
  std::vector<int> found(img.total(), -1);
  for (int i = 0; i < fast.numRaw(); ++i) found[fast.rawCorners()[i].y * img.cols + fast.rawCorners()[i].x] = fast.rawCorners()[i].score;
  int corners = 0;
  for (int y = border; y < img.rows - border; ++y) {
    for (int x = border; x < img.cols - border; ++x) {
      const int score = bruteForceScore(img, x, y);
      const bool is_corner = score > threshold;
      corners += is_corner;
      ASSERT_EQ(found[y * img.cols + x] >= 0, is_corner) << "at " << x << "," << y << " score " << score;
      if (is_corner) {
        ASSERT_EQ(found[y * img.cols + x], score) << "at " << x << "," << y;
      }
    }
  }
  EXPECT_GT(corners, 50);  // the image must exercise the detector
  // Suppression keeps only 3x3 maxima.
  const int kept = fast.suppress();
  EXPECT_GT(kept, 0);
  EXPECT_LT(kept, corners);
  for (int i = 0; i < kept; ++i) {
    const FastCorner& c = fast.corners()[i];
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) EXPECT_LE(std::max(found[(c.y + dy) * img.cols + c.x + dx], 0), c.score);
  }
}

// The vector scan (16 pixels a block: SSE2 on x86-64, NEON on aarch64) against the scalar
// reference fastScore() in raster order: for every threshold 1..254, on noise, blurred noise and
// flat patches with steps (ties at exactly the threshold), widths that are not multiples of 16,
// regions narrower than a block (scalar path), regions ending at the image edge and inside it.
TEST(FastDetector, VectorScanEqualsScalarReferenceForEveryThreshold) {
  cv::RNG rng(22);
  int images = 0, corners_checked = 0;
  for (const int width : {16 + 6, 31, 32 + 6, 47, 53, 70}) {
    for (int kind = 0; kind < 3; ++kind) {
      const int height = 24;
      cv::Mat img(height, width, CV_8UC1);
      rng.fill(img, cv::RNG::UNIFORM, 0, 256);
      if (kind == 1) cv::GaussianBlur(img, img, cv::Size(3, 3), 0.8);
      if (kind == 2) {  // 4x4 patches of a few levels 10 apart: differences hit thresholds exactly
        for (int y = 0; y < height; ++y)
          for (int x = 0; x < width; ++x) img.at<uint8_t>(y, x) = uint8_t(100 + 10 * (((x / 4) * 7 + (y / 4) * 3) % 5));
      }
      ++images;
      std::vector<int> reference(img.total(), 0);
      for (int y = 3; y < height - 3; ++y) {
        for (int x = 3; x < width - 3; ++x) {
          reference[y * width + x] = fastScore(img.ptr<uint8_t>(y) + x, static_cast<int>(img.step[0]));
          ASSERT_EQ(reference[y * width + x], bruteForceScore(img, x, y)) << "at " << x << "," << y;
        }
      }
      FastDetector fast(width, height, 4096);
      for (int threshold = 1; threshold <= 254; ++threshold) {
        const int border = 3 + threshold % 3;
        // Regions: the whole image, then a left part, a narrow strip and the rest of a band.
        const int split = 3 + threshold % (width - 6), narrow = std::min(width, split + 1 + threshold % 15);
        const int regions[4][4] = {{0, 0, width, height / 2},
                                   {0, height / 2, split, height},
                                   {split, height / 2, narrow, height},
                                   {narrow, height / 2, width, height}};
        fast.begin(img, border);
        std::vector<FastCorner> expected;
        for (const auto& r : regions) {
          fast.scan(threshold, r[0], r[1], r[2], r[3]);
          for (int y = std::max(r[1], border); y < std::min(r[3], height - border); ++y) {
            for (int x = std::max(r[0], border); x < std::min(r[2], width - border); ++x) {
              if (reference[y * width + x] > threshold) expected.push_back({int16_t(x), int16_t(y), uint8_t(reference[y * width + x])});
            }
          }
        }
        ASSERT_EQ(fast.numRaw(), static_cast<int>(expected.size())) << "width " << width << " kind " << kind << " threshold " << threshold;
        for (size_t i = 0; i < expected.size(); ++i) {
          const FastCorner& got = fast.rawCorners()[i];
          ASSERT_TRUE(got.x == expected[i].x && got.y == expected[i].y && got.score == expected[i].score)
              << "corner " << i << ": got " << got.x << "," << got.y << " score " << int(got.score) << ", expected "
              << expected[i].x << "," << expected[i].y << " score " << int(expected[i].score) << " (width " << width
              << " kind " << kind << " threshold " << threshold << ")";
        }
        corners_checked += static_cast<int>(expected.size());
      }
    }
  }
  EXPECT_EQ(images, 18);
  EXPECT_GT(corners_checked, 20000);  // the images must exercise the detector at many thresholds
}

// Rows wider than the scan's buffer of blocks that passed the compass tests (64 blocks of 16):
// a row of noise then passes it in several rounds, which must keep raster order.
TEST(FastDetector, VectorScanOfRowsWiderThanItsBlockBuffer) {
  const int width = 16 * 64 * 2 + 37, height = 10;
  cv::Mat img(height, width, CV_8UC1);
  cv::RNG rng(2222);
  rng.fill(img, cv::RNG::UNIFORM, 0, 256);
  FastDetector fast(width, height, 40000);
  for (const int threshold : {1, 10, 40}) {
    fast.begin(img, 3);
    fast.scan(threshold, 0, 0, width, height);
    int expected = 0;
    for (int y = 3; y < height - 3; ++y) {
      for (int x = 3; x < width - 3; ++x) {
        const int score = fastScore(img.ptr<uint8_t>(y) + x, static_cast<int>(img.step[0]));
        if (score <= threshold) continue;
        ASSERT_LT(expected, fast.numRaw()) << "threshold " << threshold;
        const FastCorner& got = fast.rawCorners()[expected++];
        ASSERT_TRUE(got.x == x && got.y == y && got.score == score)
            << "threshold " << threshold << ": got " << got.x << "," << got.y << " score " << int(got.score)
            << ", expected " << x << "," << y << " score " << score;
      }
    }
    EXPECT_EQ(fast.numRaw(), expected) << "threshold " << threshold;
    EXPECT_GT(expected, 1000) << "threshold " << threshold;  // most blocks pass the compass tests
  }
}

TEST(OrbExtraction, RealFrameGivesAboutOneThousandUndistortedKeypoints) {
  RgbdImage frame;
  if (!test::loadTumRpyFrame(10, &frame)) GTEST_SKIP() << "TUM fr1/rpy not found under " << test::tumRpyDir();
  const PinholeCamera camera = test::tum1Camera();
  FeatureExtractor extractor(camera, ExtractorOptions());
  auto features = std::make_unique<FrameFeatures>();
  ASSERT_TRUE(extractor.extract(frame, *features));
  EXPECT_GE(features->keypoints.size(), 950u);
  EXPECT_LE(features->keypoints.size(), 1000u);
  ASSERT_EQ(features->keypoints.size(), features->keypoint_descriptors.size());
  std::array<int, kPyramidLevels> per_level{};
  int with_depth = 0;
  for (const KeypointObservation& kp : features->keypoints) {
    ASSERT_TRUE(camera.inImage(kp.px.x(), kp.px.y()));
    ASSERT_GE(kp.octave, 0);
    ASSERT_LT(kp.octave, kPyramidLevels);
    ++per_level[kp.octave];
    const Eigen::Vector2d u = camera.undistortPoint(kp.px.x(), kp.px.y());
    EXPECT_NEAR(kp.px_undist.x(), u.x(), 1e-3);
    EXPECT_NEAR(kp.px_undist.y(), u.y(), 1e-3);
    EXPECT_GE(kp.angle_deg, 0.f);
    EXPECT_LT(kp.angle_deg, 360.f);
    if (kp.depth_m > 0) {
      ++with_depth;
      // u_r = u - fx b / d and P_cam back-projects px_undist.
      EXPECT_NEAR(kp.u_right, kp.px_undist.x() - camera.fx * camera.baseline_m / kp.depth_m, 1e-3);
      const Eigen::Vector2d reprojected = camera.project(kp.P_cam.cast<double>());
      EXPECT_NEAR(reprojected.x(), kp.px_undist.x(), 1e-2);
      EXPECT_GT(kp.info_uvr.determinant(), 0.f);
    } else {
      EXPECT_EQ(kp.u_right, -1.f);
      EXPECT_TRUE(kp.info_uvr.isZero());
    }
  }
  for (int level = 0; level < kPyramidLevels; ++level) EXPECT_GT(per_level[level], 10) << "level " << level;
  EXPECT_GT(with_depth, 700);
  // Distortion is applied: somewhere near the border the undistorted coordinate moved.
  float max_shift = 0;
  for (const KeypointObservation& kp : features->keypoints) max_shift = std::max(max_shift, (kp.px - kp.px_undist).norm());
  EXPECT_GT(max_shift, 2.f);
}

TEST(OrbExtraction, SameInputGivesIdenticalOutput) {
  auto scene = test::makeScene("textured", 3);
  ASSERT_TRUE(scene);
  const RgbdImage frame = test::renderFrame(*scene, 5);
  FeatureExtractor a(scene->camera(), ExtractorOptions()), b(scene->camera(), ExtractorOptions());
  auto fa = std::make_unique<FrameFeatures>(), fb = std::make_unique<FrameFeatures>(), fc = std::make_unique<FrameFeatures>();
  ASSERT_TRUE(a.extract(frame, *fa));
  ASSERT_TRUE(b.extract(frame, *fb));
  ASSERT_TRUE(a.extract(frame, *fc));  // the same extractor again: no state leaks between frames
  ASSERT_GT(fa->keypoints.size(), 500u);
  for (const FrameFeatures* other : {fb.get(), fc.get()}) {
    ASSERT_EQ(fa->keypoints.size(), other->keypoints.size());
    ASSERT_EQ(fa->lines.size(), other->lines.size());
    for (size_t i = 0; i < fa->keypoints.size(); ++i) {
      ASSERT_EQ(fa->keypoints[i].px, other->keypoints[i].px);
      ASSERT_EQ(fa->keypoint_descriptors[i].words, other->keypoint_descriptors[i].words);
    }
    for (size_t i = 0; i < fa->lines.size(); ++i) {
      ASSERT_EQ(fa->lines[i].start_px, other->lines[i].start_px);
      ASSERT_EQ(fa->line_descriptors[i].words, other->line_descriptors[i].words);
      ASSERT_EQ(fa->lines[i].num_samples, other->lines[i].num_samples);
    }
  }
}

TEST(OrbExtraction, DescriptorsEqualThoseOnTheWholeBlurredPyramid) {
  // OrbExtractor blurs only the columns each keypoint's tests read (bands of rows, from its
  // orientation bin): describing every keypoint again on a pyramid blurred everywhere must give
  // the same bits. Frames in sequence through one extractor, so that a sample left unblurred
  // would read an older frame's value (or the initial zeros) and differ.
  auto scene = test::makeScene("textured", 6);
  ASSERT_TRUE(scene);
  OrbExtractor extractor(scene->camera(), ExtractorOptions());
  int compared = 0;
  std::vector<int> per_level(kPyramidLevels, 0);
  for (int frame_index : {0, 7, 14}) {
    const RgbdImage frame = test::renderFrame(*scene, frame_index);
    cv::Mat grey;
    cv::cvtColor(frame.bgr, grey, cv::COLOR_BGR2GRAY);
    auto features = std::make_unique<FrameFeatures>();
    extractor.extract(grey, *features);
    ASSERT_GT(features->keypoints.size(), 500u);
    const ImagePyramid& partial = extractor.pyramid();
    ImagePyramid whole(grey.cols, grey.rows, partial.numLevels(), ExtractorOptions().scale_factor);
    whole.build(grey);
    const OrbDescriber describer(whole.stride());
    for (size_t i = 0; i < features->keypoints.size(); ++i) {
      const KeypointObservation& kp = features->keypoints[i];
      const float scale = whole.scale(kp.octave);
      const int x = static_cast<int>(std::lround(kp.px.x() / scale)), y = static_cast<int>(std::lround(kp.px.y() / scale));
      ASSERT_EQ(kp.px.x(), x * scale);
      Descriptor256 expected;
      describer.describe(whole.blurred(kp.octave).ptr<uint8_t>(y) + x, kp.angle_deg, expected);
      ASSERT_EQ(features->keypoint_descriptors[i].words, expected.words)
          << "frame " << frame_index << ", keypoint " << i << " at " << x << "," << y << " level " << int(kp.octave);
      ++per_level[kp.octave];
      ++compared;
    }
  }
  EXPECT_GT(compared, 1500);
  for (int level = 0; level < ExtractorOptions().num_levels; ++level) EXPECT_GT(per_level[level], 0) << "level " << level;
}

TEST(OrbExtraction, OrientationAndDescriptorFollowAnImageRotation) {
  auto scene = test::makeScene("textured", 4);
  ASSERT_TRUE(scene);
  RgbdImage frame = test::renderFrame(*scene, 0);
  // A 90-degree rotation of a 640x480 image is 480x640: use a square crop so one camera fits both.
  PinholeCamera camera = scene->camera();
  camera.width = camera.height = 480;
  camera.cx = camera.cy = 239.5;
  RgbdImage square, rotated;
  square.bgr = frame.bgr(cv::Rect(80, 0, 480, 480)).clone();
  cv::rotate(square.bgr, rotated.bgr, cv::ROTATE_90_CLOCKWISE);  // (x, y) -> (479 - y, x)
  FeatureExtractor extractor(camera, ExtractorOptions());
  auto fa = std::make_unique<FrameFeatures>(), fb = std::make_unique<FrameFeatures>();
  ASSERT_TRUE(extractor.extract(square, *fa));
  ASSERT_TRUE(extractor.extract(rotated, *fb));
  std::vector<int> distances;
  std::vector<float> angle_errors;
  for (size_t i = 0; i < fa->keypoints.size(); ++i) {
    const KeypointObservation& a = fa->keypoints[i];
    const Eigen::Vector2f expected(479 - a.px.y(), a.px.x());
    for (size_t j = 0; j < fb->keypoints.size(); ++j) {
      const KeypointObservation& b = fb->keypoints[j];
      if (b.octave != a.octave || (b.px - expected).norm() > 1.5f) continue;
      distances.push_back(hammingDistance(fa->keypoint_descriptors[i], fb->keypoint_descriptors[j]));
      float diff = std::fmod(b.angle_deg - a.angle_deg + 720.f, 360.f);
      angle_errors.push_back(std::abs(diff - 90.f));
      break;
    }
  }
  ASSERT_GT(distances.size(), 100u) << "too few keypoints re-detected after rotation";
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
  std::nth_element(angle_errors.begin(), angle_errors.begin() + angle_errors.size() / 2, angle_errors.end());
  EXPECT_LT(distances[distances.size() / 2], 40) << "median Hamming distance of re-detected keypoints";
  EXPECT_LT(angle_errors[angle_errors.size() / 2], 8.f) << "median orientation error (deg)";
}

TEST(OrbExtraction, LowTextureCellsWithTextureGetKeypoints) {
  auto scene = test::makeScene("low_texture", 2);
  ASSERT_TRUE(scene);
  FeatureExtractor extractor(scene->camera(), ExtractorOptions());
  auto features = std::make_unique<FrameFeatures>();
  double worst = 1.0;
  for (int i : {0, 60, 120}) {
    const RgbdImage frame = test::renderFrame(*scene, i);
    ASSERT_TRUE(extractor.extract(frame, *features));
    cv::Mat grey, gx, gy, magnitude;
    cv::cvtColor(frame.bgr, grey, cv::COLOR_BGR2GRAY);
    cv::Sobel(grey, gx, CV_32F, 1, 0);
    cv::Sobel(grey, gy, CV_32F, 0, 1);
    cv::magnitude(gx, gy, magnitude);
    // 8x6 cells; a cell "contains texture" when some pixel (away from the image border, where no
    // detector can work) has a clear gradient: Sobel magnitude > 80 (~20 grey levels per pixel).
    const int cols = 8, rows = 6, cw = frame.bgr.cols / cols, ch = frame.bgr.rows / rows;
    int textured = 0, covered = 0;
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        cv::Rect cell(c * cw, r * ch, cw, ch);
        cell &= cv::Rect(20, 20, frame.bgr.cols - 40, frame.bgr.rows - 40);
        double max_gradient = 0;
        cv::minMaxLoc(magnitude(cell), nullptr, &max_gradient);
        if (max_gradient < 80) continue;
        ++textured;
        for (const KeypointObservation& kp : features->keypoints) {
          if (kp.px.x() >= c * cw && kp.px.x() < (c + 1) * cw && kp.px.y() >= r * ch && kp.px.y() < (r + 1) * ch) {
            ++covered;
            break;
          }
        }
      }
    }
    ASSERT_GT(textured, 10) << "frame " << i << " has almost no texture; the test needs some";
    const double fraction = static_cast<double>(covered) / textured;
    RecordProperty("covered_fraction_frame_" + std::to_string(i), std::to_string(fraction));
    worst = std::min(worst, fraction);
    EXPECT_GE(fraction, 0.6) << "frame " << i << ": " << covered << " of " << textured << " textured cells";
  }
  std::printf("low-texture spread: worst frame covers %.0f%% of textured cells\n", 100 * worst);
}

}  // namespace
}  // namespace plumb

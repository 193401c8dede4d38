// drivers/image/: the libpng encoder and the libjpeg decoder that replaced OpenCV's imgcodecs in
// the product. Oracle: OpenCV's imgcodecs itself (linked into tests only). The encoder uses the
// settings OpenCV uses for the same parameters, so the PNG bytes must be identical, and they must
// decode to the original pixels; the JPEG decoder must give the pixels cv::imdecode gives.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "drivers/image/jpeg_decoder.h"
#include "drivers/image/png_encoder.h"

namespace plumb {
namespace {

// Deterministic content with structure (gradients + noise) so filters and zlib have work to do.
cv::Mat testImage(int rows, int cols, int type) {
  cv::Mat image(rows, cols, type);
  cv::RNG rng(7);
  rng.fill(image, cv::RNG::UNIFORM, 0, image.depth() == CV_16U ? 6000 : 256);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols / 2; ++c) {
      uint8_t* p = image.ptr<uint8_t>(r) + c * image.elemSize();
      for (size_t b = 0; b < image.elemSize(); ++b) p[b] = static_cast<uint8_t>(r + c + b);
    }
  }
  return image;
}

bool sameImage(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

TEST(PngEncoder, BytesMatchOpenCvForTheSettingsPlumbUses) {
  for (int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3}) {
    const cv::Mat image = testImage(37, 53, type);
    // Recording frames: level N + RLE.
    for (int level : {0, 1, 6}) {
      std::vector<uint8_t> ours, theirs;
      PngEncodeOptions options;
      options.compression_level = level;
      options.rle_strategy = true;
      ASSERT_TRUE(encodePng(image, options, ours).ok());
      ASSERT_TRUE(cv::imencode(".png", image, theirs,
                               {cv::IMWRITE_PNG_COMPRESSION, level, cv::IMWRITE_PNG_STRATEGY,
                                cv::IMWRITE_PNG_STRATEGY_RLE}));
      EXPECT_EQ(ours, theirs) << "type " << type << " level " << level;
    }
    // TUM folder writer: level 1, default strategy.
    std::vector<uint8_t> ours, theirs;
    PngEncodeOptions level1;
    ASSERT_TRUE(encodePng(image, level1, ours).ok());
    ASSERT_TRUE(cv::imencode(".png", image, theirs, {cv::IMWRITE_PNG_COMPRESSION, 1}));
    EXPECT_EQ(ours, theirs) << "type " << type;
    // Plots and synthetic datasets: imwrite without parameters.
    ours.clear();
    ASSERT_TRUE(encodePng(image, pngFastestOptions(), ours).ok());
    ASSERT_TRUE(cv::imencode(".png", image, theirs));
    EXPECT_EQ(ours, theirs) << "type " << type;
    // And it decodes (OpenCV's decoder) to the original pixels.
    EXPECT_TRUE(sameImage(cv::imdecode(ours, cv::IMREAD_UNCHANGED), image)) << "type " << type;
  }
}

TEST(PngEncoder, AppendsAndRefusesWhatPngCannotHold) {
  std::vector<uint8_t> out = {1, 2, 3};
  const cv::Mat image = testImage(4, 5, CV_8UC3);
  ASSERT_TRUE(encodePng(image, PngEncodeOptions{}, out).ok());
  EXPECT_EQ(out[0], 1);
  EXPECT_EQ(out[3], 0x89);  // PNG signature after the existing bytes
  const std::size_t size = out.size();
  EXPECT_FALSE(encodePng(cv::Mat(4, 5, CV_32FC1, cv::Scalar(1)), PngEncodeOptions{}, out).ok());
  EXPECT_FALSE(encodePng(cv::Mat(4, 5, CV_8UC2, cv::Scalar(1)), PngEncodeOptions{}, out).ok());
  EXPECT_FALSE(encodePng(cv::Mat(), PngEncodeOptions{}, out).ok());
  PngEncodeOptions bad_level;
  bad_level.compression_level = 10;
  EXPECT_FALSE(encodePng(image, bad_level, out).ok());
  EXPECT_EQ(out.size(), size);  // nothing appended on error
}

TEST(PngEncoder, WritesAFileAndNamesItOnError) {
  const std::string path = ::testing::TempDir() + "/plumb_png_encoder_test.png";
  const cv::Mat image = testImage(9, 11, CV_16UC1);
  ASSERT_TRUE(writePngFile(path, image, PngEncodeOptions{}).ok());
  EXPECT_TRUE(sameImage(cv::imread(path, cv::IMREAD_UNCHANGED), image));
  std::remove(path.c_str());
  const std::string missing = ::testing::TempDir() + "/no_such_folder_plumb/x.png";
  const Status st = writePngFile(missing, image, PngEncodeOptions{});
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find(missing), std::string::npos) << st.message();
}

TEST(JpegDecoder, GivesOpenCvsPixelsForColourAndGrey) {
  if (!jpegAvailable()) GTEST_SKIP() << "built without libjpeg";
  for (int type : {CV_8UC3, CV_8UC1}) {
    const cv::Mat image = testImage(24, 40, type);
    std::vector<uint8_t> jpeg;
    ASSERT_TRUE(cv::imencode(".jpg", image, jpeg, {cv::IMWRITE_JPEG_QUALITY, 90}));
    cv::Mat ours;
    std::string error;
    ASSERT_TRUE(decodeJpeg(jpeg.data(), jpeg.size(), ours, &error)) << error;
    EXPECT_TRUE(sameImage(ours, cv::imdecode(jpeg, cv::IMREAD_UNCHANGED))) << "type " << type;
  }
}

TEST(JpegDecoder, CorruptOrForeignBytesAreAnError) {
  if (!jpegAvailable()) GTEST_SKIP() << "built without libjpeg";
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", testImage(16, 16, CV_8UC3), jpeg));
  cv::Mat out;
  std::string error;
  EXPECT_FALSE(decodeJpeg(jpeg.data(), 20, out, &error));  // header cut off
  EXPECT_NE(error.find("JPEG"), std::string::npos) << error;
  const uint8_t png_signature[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  EXPECT_FALSE(looksLikeJpeg(png_signature, sizeof(png_signature)));
  EXPECT_FALSE(decodeJpeg(png_signature, sizeof(png_signature), out, &error));
}

}  // namespace
}  // namespace plumb

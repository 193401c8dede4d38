// drivers/image/jpeg_encoder.h: BGR in, a JPEG that the decoder (and so any viewer) reads back as
// the same image within JPEG's loss; bad arguments refused with a message.
#include "drivers/image/jpeg_encoder.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <vector>

#include "drivers/image/jpeg_decoder.h"

namespace plumb {
namespace {

TEST(JpegEncoder, RoundTripsThroughTheDecoderInBgrOrder) {
  if (!jpegAvailable()) GTEST_SKIP() << "built without libjpeg";
  const int width = 64, height = 48;
  std::vector<uint8_t> bgr(std::size_t(width * height * 3));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      uint8_t* p = &bgr[std::size_t((y * width + x) * 3)];
      p[0] = uint8_t(4 * x);    // blue grows to the right
      p[1] = uint8_t(5 * y);    // green downwards
      p[2] = 200;               // red constant
    }
  }
  std::vector<uint8_t> jpeg;
  std::string error;
  ASSERT_TRUE(encodeJpeg(bgr.data(), width, height, std::size_t(width) * 3, 90, &jpeg, &error)) << error;
  ASSERT_TRUE(looksLikeJpeg(jpeg.data(), jpeg.size()));
  cv::Mat decoded;
  ASSERT_TRUE(decodeJpeg(jpeg.data(), jpeg.size(), decoded, &error)) << error;
  ASSERT_EQ(decoded.cols, width);
  ASSERT_EQ(decoded.rows, height);
  double sum = 0;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const cv::Vec3b d = decoded.at<cv::Vec3b>(y, x);
      const uint8_t* p = &bgr[std::size_t((y * width + x) * 3)];
      for (int c = 0; c < 3; ++c) sum += std::abs(int(d[c]) - int(p[c]));
    }
  }
  EXPECT_LT(sum / (width * height * 3), 3.0);  // channels not swapped, quality 90
}

TEST(JpegEncoder, RefusesBadArguments) {
  std::vector<uint8_t> jpeg;
  std::string error;
  const uint8_t pixel[3] = {0, 0, 0};
  EXPECT_FALSE(encodeJpeg(pixel, 0, 1, 3, 75, &jpeg, &error));
  EXPECT_FALSE(error.empty());
  EXPECT_FALSE(encodeJpeg(pixel, 1, 1, 3, 101, &jpeg, &error));
}

}  // namespace
}  // namespace plumb

// V4L2 buffer conversions against pixels whose values are known by construction.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "drivers/v4l2/pixel_formats.h"

namespace plumb {
namespace {

TEST(V4l2PixelFormats, YuyvBt601LimitedRangeKnownColours) {
  // Two rows, stride 12 (8 bytes of pixels + 4 of padding the converter must skip).
  const uint8_t yuyv[] = {
      16, 128, 235, 128,  81, 90, 81, 240,  0xEE, 0xEE, 0xEE, 0xEE,  // black, white | red, red
      145, 54, 145, 34,  126, 128, 126, 128,  0xEE, 0xEE, 0xEE, 0xEE};  // green, green | grey
  cv::Mat bgr;
  yuyvToBgr(yuyv, 4, 2, 12, bgr);
  ASSERT_EQ(bgr.type(), CV_8UC3);
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 1), cv::Vec3b(255, 255, 255));
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 2), cv::Vec3b(0, 0, 255));  // BT.601 red (81, 90, 240)
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 3), cv::Vec3b(0, 0, 255));
  // Y 126, U = V = 128: grey (126 - 16) * 255 / 219 = 128.08 -> 128.
  EXPECT_EQ(bgr.at<cv::Vec3b>(1, 2), cv::Vec3b(128, 128, 128));
  EXPECT_EQ(bgr.at<cv::Vec3b>(1, 3), cv::Vec3b(128, 128, 128));
  // BT.601 green (145, 54, 34): B = (298*129 + 516*(-74) + 128) >> 8 = 1, G saturates, R = 0.
  EXPECT_EQ(bgr.at<cv::Vec3b>(1, 0), cv::Vec3b(1, 255, 0));
  EXPECT_EQ(bgr.at<cv::Vec3b>(1, 1), cv::Vec3b(1, 255, 0));
}

TEST(V4l2PixelFormats, GreyIsCopiedToAllThreeChannels) {
  const uint8_t grey[] = {0, 7, 200, 255, /*pad*/ 1, 2};
  cv::Mat bgr;
  greyToBgr(grey, 2, 2, 3, bgr);  // stride 3: rows {0, 7} and {255, 1}
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 1), cv::Vec3b(7, 7, 7));
  EXPECT_EQ(bgr.at<cv::Vec3b>(1, 0), cv::Vec3b(255, 255, 255));
  EXPECT_EQ(bgr.at<cv::Vec3b>(1, 1), cv::Vec3b(1, 1, 1));
}

TEST(V4l2PixelFormats, Z16IsLittleEndianAndExact) {
  const uint8_t z16[] = {0x00, 0x00, 0x34, 0x12, 0xEE, 0xEE,  // 0, 0x1234, pad
                         0xFF, 0xFF, 0xE8, 0x03, 0xEE, 0xEE};  // 65535, 1000, pad
  cv::Mat depth;
  z16ToDepth(z16, 2, 2, 6, depth);
  ASSERT_EQ(depth.type(), CV_16UC1);
  EXPECT_EQ(depth.at<uint16_t>(0, 0), 0);
  EXPECT_EQ(depth.at<uint16_t>(0, 1), 0x1234);
  EXPECT_EQ(depth.at<uint16_t>(1, 0), 65535);
  EXPECT_EQ(depth.at<uint16_t>(1, 1), 1000);
}

TEST(V4l2PixelFormats, MjpegDecodesAndChecksTheSize) {
  cv::Mat original(16, 24, CV_8UC3, cv::Scalar(40, 120, 200));
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", original, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95}));
  cv::Mat bgr;
  ASSERT_TRUE(mjpegToBgr(jpeg.data(), jpeg.size(), 24, 16, bgr));
  const cv::Vec3b p = bgr.at<cv::Vec3b>(8, 12);  // JPEG is lossy: a flat colour stays close
  EXPECT_NEAR(p[0], 40, 3);
  EXPECT_NEAR(p[1], 120, 3);
  EXPECT_NEAR(p[2], 200, 3);
  EXPECT_FALSE(mjpegToBgr(jpeg.data(), jpeg.size(), 32, 16, bgr));       // wrong size
  EXPECT_FALSE(mjpegToBgr(jpeg.data(), jpeg.size() / 3, 24, 16, bgr));   // truncated frame
  EXPECT_FALSE(mjpegToBgr(jpeg.data(), 0, 24, 16, bgr));
}

}  // namespace
}  // namespace plumb

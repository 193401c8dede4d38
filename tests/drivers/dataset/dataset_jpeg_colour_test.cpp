// A TUM-layout folder whose colour images are JPEG (converted datasets): decoded by libjpeg
// (drivers/image/jpeg_decoder.h) to the pixels cv::imdecode gives; a JPEG depth map is refused
// (8-bit), and a file that is neither PNG nor JPEG is an error naming the file.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "tests/drivers/dataset_test_support.h"
#include "drivers/image/jpeg_decoder.h"
#include "drivers/open/open_source.h"

namespace plumb {
namespace {

std::string encode(const char* ext, const cv::Mat& image) {
  std::vector<uchar> bytes;
  EXPECT_TRUE(cv::imencode(ext, image, bytes));
  return std::string(bytes.begin(), bytes.end());
}

cv::Mat colourPattern() {
  cv::Mat image(480, 640, CV_8UC3);
  for (int r = 0; r < image.rows; ++r)
    for (int c = 0; c < image.cols; ++c) image.at<cv::Vec3b>(r, c) = cv::Vec3b(c % 256, r % 256, (r + c) % 256);
  return image;
}

TEST(TumJpegColour, JpegColourDecodesAsOpenCvDoes) {
  if (!jpegAvailable()) GTEST_SKIP() << "built without libjpeg";
  testing::TempDir dir;
  const std::string jpeg = encode(".jpg", colourPattern());
  dir.write("seq/rgb/1.000000.jpg", jpeg);
  dir.write("seq/depth/1.000000.png", encode(".png", cv::Mat(480, 640, CV_16UC1, cv::Scalar(5000))));
  dir.write("seq/associations.txt", "1.000000 rgb/1.000000.jpg 1.000000 depth/1.000000.png\n");
  std::unique_ptr<FrameSource> source;
  const Status st = openFrameSource(dir.file("seq"), "tum1", &source);
  ASSERT_TRUE(st.ok()) << st.message();
  RgbdImage frame;
  ASSERT_EQ(source->next(frame), SourceResult::kFrame) << source->lastError().message();
  const cv::Mat expected = cv::imdecode(std::vector<uchar>(jpeg.begin(), jpeg.end()), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(frame.bgr.type(), CV_8UC3);
  EXPECT_EQ(cv::norm(frame.bgr, expected, cv::NORM_INF), 0);
  EXPECT_EQ(frame.depth_raw.at<uint16_t>(10, 10), 5000);
}

TEST(TumJpegColour, JpegDepthAndForeignFilesAreErrorsNamingTheFile) {
  struct Case {
    std::string depth_name, depth_bytes, expected;
  };
  const Case cases[] = {
      {"depth/1.000000.jpg", encode(".jpg", cv::Mat(480, 640, CV_8UC1, cv::Scalar(50))), "depth/1.000000.jpg"},
      {"depth/1.000000.png", "GIF89a not an image we read", "not an image"},
  };
  for (const Case& c : cases) {
    testing::TempDir dir;
    dir.write("seq/rgb/1.000000.png", encode(".png", colourPattern()));
    dir.write("seq/" + c.depth_name, c.depth_bytes);
    dir.write("seq/associations.txt", "1.000000 rgb/1.000000.png 1.000000 " + c.depth_name + "\n");
    std::unique_ptr<FrameSource> source;
    ASSERT_TRUE(openFrameSource(dir.file("seq"), "tum1", &source).ok());
    RgbdImage frame;
    EXPECT_EQ(source->next(frame), SourceResult::kError) << c.depth_name;
    EXPECT_NE(source->lastError().message().find(c.expected), std::string::npos) << source->lastError().message();
    EXPECT_NE(source->lastError().message().find(c.depth_name), std::string::npos) << source->lastError().message();
  }
}

}  // namespace
}  // namespace plumb

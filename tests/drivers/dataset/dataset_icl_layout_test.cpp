// ICL-NUIM in TUM format: integer frame-index timestamps, depth-first associations, camera `icl`
// (negative fy) chosen from the folder name.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "tests/drivers/dataset_test_support.h"
#include "drivers/open/open_source.h"

namespace plumb {
namespace {

std::string png(const cv::Mat& image) {
  std::vector<uchar> bytes;
  EXPECT_TRUE(cv::imencode(".png", image, bytes));
  return std::string(bytes.begin(), bytes.end());
}

TEST(IclLayout, DepthFirstAssociationsAndIclCameraFromFolderName) {
  testing::TempDir dir;
  const std::string root = "living_room_traj0_frei_png";
  for (int i = 0; i < 2; ++i) {
    // Frame i is recognisable: colour value 10 + i, depth 1000 * (i + 1).
    dir.write(root + "/rgb/" + std::to_string(i) + ".png",
              png(cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(10 + i))));
    dir.write(root + "/depth/" + std::to_string(i) + ".png",
              png(cv::Mat(480, 640, CV_16UC1, cv::Scalar(1000 * (i + 1)))));
  }
  dir.write(root + "/associations.txt", "0 depth/0.png 0 rgb/0.png\n1 depth/1.png 1 rgb/1.png\n");

  std::unique_ptr<FrameSource> source;
  const Status st = openFrameSource(dir.file(root), "", &source);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_EQ(source->camera().fy, -480.0);
  EXPECT_EQ(source->camera().fx, 481.2);
  RgbdImage frame;
  for (int i = 0; i < 2; ++i) {
    ASSERT_EQ(source->next(frame), SourceResult::kFrame) << source->lastError().message();
    EXPECT_EQ(frame.timestamp_s, i);
    EXPECT_EQ(frame.bgr.at<cv::Vec3b>(0, 0)[0], 10 + i);
    EXPECT_EQ(frame.depth_raw.at<uint16_t>(479, 639), 1000 * (i + 1));
  }
  EXPECT_EQ(source->next(frame), SourceResult::kEndOfStream);
}

}  // namespace
}  // namespace plumb

// Every bad dataset input gives one clear Status naming the file (and line), never a crash.
// The datasets are tiny (8x6 pixels) folders written into a private temp dir.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "tests/drivers/dataset_test_support.h"
#include "drivers/open/open_source.h"
#include "drivers/dataset/tum_dataset.h"

namespace plumb {
namespace {

using testing::TempDir;

constexpr int kWidth = 8, kHeight = 6;

PinholeCamera tinyCamera() {
  PinholeCamera camera;
  camera.fx = camera.fy = 10;
  camera.cx = 3.5;
  camera.cy = 2.5;
  camera.width = kWidth;
  camera.height = kHeight;
  return camera;
}

std::string pngBytes(const cv::Mat& image) {
  std::vector<uchar> bytes;
  EXPECT_TRUE(cv::imencode(".png", image, bytes));
  return std::string(bytes.begin(), bytes.end());
}

cv::Mat colour(int width = kWidth, int height = kHeight) {
  return cv::Mat(height, width, CV_8UC3, cv::Scalar(10, 20, 30));
}
cv::Mat depth(int width = kWidth, int height = kHeight) {
  return cv::Mat(height, width, CV_16UC1, cv::Scalar(5000));
}

// A valid two-frame dataset; tests then break one thing.
class BadDataset : public ::testing::Test {
 protected:
  void SetUp() override {
    write("rgb/1.000000.png", pngBytes(colour()));
    write("rgb/1.033333.png", pngBytes(colour()));
    write("depth/1.005000.png", pngBytes(depth()));
    write("depth/1.038000.png", pngBytes(depth()));
    write("rgb.txt", "# color images\n1.000000 rgb/1.000000.png\n1.033333 rgb/1.033333.png\n");
    write("depth.txt", "# depth\n1.005000 depth/1.005000.png\n1.038000 depth/1.038000.png\n");
  }

  Status open(std::unique_ptr<TumDatasetSource>* source) {
    return TumDatasetSource::open(root(), tinyCamera(), source);
  }
  // Opens (must succeed) and loads frame `i`, returning the load status.
  Status loadFrame(std::size_t i) {
    std::unique_ptr<TumDatasetSource> source;
    const Status st = open(&source);
    EXPECT_TRUE(st.ok()) << st.message();
    if (!st.ok()) return st;
    RgbdImage frame;
    return source->load(i, frame);
  }
  static void expectMentions(const Status& st, const std::string& a, const std::string& b = "") {
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.message().find(a), std::string::npos) << st.message();
    if (!b.empty()) {
      EXPECT_NE(st.message().find(b), std::string::npos) << st.message();
    }
  }

  // The dataset sits in <temp>/seq: a fixed folder name that names no sensor.
  std::string root() const { return dir_.file("seq"); }
  std::string file(const std::string& relative) const { return root() + "/" + relative; }
  void write(const std::string& relative, const std::string& content) const {
    dir_.write("seq/" + relative, content);
  }

  TempDir dir_;
};

TEST_F(BadDataset, TheValidFixtureLoads) {
  std::unique_ptr<TumDatasetSource> source;
  ASSERT_TRUE(open(&source).ok());
  ASSERT_EQ(source->size(), 2u);
  RgbdImage frame;
  EXPECT_EQ(source->next(frame), SourceResult::kFrame);
  EXPECT_EQ(frame.depth_raw.at<uint16_t>(0, 0), 5000);
  EXPECT_EQ(source->next(frame), SourceResult::kFrame);
  EXPECT_EQ(source->next(frame), SourceResult::kEndOfStream);
}

// A list may only name files inside the dataset folder: "..", absolute paths are refused at open
// with the list's file and line, and nothing outside the folder is read.
TEST_F(BadDataset, ListEntriesOutsideTheFolderAreRefused) {
  for (const std::string bad : {"../../../etc/passwd", "/etc/passwd", "rgb/../../x.png"}) {
    write("rgb.txt", "# color images\n1.000000 rgb/1.000000.png\n1.033333 " + bad + "\n");
    std::unique_ptr<TumDatasetSource> source;
    const Status st = open(&source);
    expectMentions(st, "rgb.txt:3", bad);
  }
}

TEST_F(BadDataset, MissingImageFileIsReportedAtOpen) {
  std::filesystem::remove(file("depth/1.038000.png"));
  std::unique_ptr<TumDatasetSource> source;
  expectMentions(open(&source), file("depth/1.038000.png"),
                 "missing image file (listed in rgb.txt/depth.txt)");
}

TEST_F(BadDataset, ImageFileRemovedAfterOpen) {
  std::unique_ptr<TumDatasetSource> source;
  ASSERT_TRUE(open(&source).ok());
  std::filesystem::remove(file("rgb/1.033333.png"));
  RgbdImage frame;
  EXPECT_TRUE(source->load(0, frame).ok());
  expectMentions(source->load(1, frame), file("rgb/1.033333.png"), "missing");
}

TEST_F(BadDataset, TruncatedPng) {
  const std::string bytes = pngBytes(colour());
  write("rgb/1.000000.png", bytes.substr(0, bytes.size() * 2 / 3));
  expectMentions(loadFrame(0), file("rgb/1.000000.png"), "corrupt");
}

TEST_F(BadDataset, GarbageBytesPng) {
  write("depth/1.005000.png", "this is not a PNG file at all, just text bytes");
  expectMentions(loadFrame(0), file("depth/1.005000.png"), "corrupt");
}

TEST_F(BadDataset, EmptyPngFile) {
  write("depth/1.038000.png", "");
  expectMentions(loadFrame(1), file("depth/1.038000.png"), "empty");
}

TEST_F(BadDataset, EightBitDepth) {
  write("depth/1.005000.png", pngBytes(cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(50))));
  expectMentions(loadFrame(0), file("depth/1.005000.png"), "8-bit 1-channel image, expected 16-bit");
}

TEST_F(BadDataset, SixteenBitOrGreyColour) {
  write("rgb/1.000000.png", pngBytes(cv::Mat(kHeight, kWidth, CV_16UC3, cv::Scalar(1, 2, 3))));
  expectMentions(loadFrame(0), file("rgb/1.000000.png"), "expected 8-bit 3-channel");
  write("rgb/1.000000.png", pngBytes(cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(1))));
  expectMentions(loadFrame(0), file("rgb/1.000000.png"), "expected 8-bit 3-channel");
}

TEST_F(BadDataset, WrongImageSize) {
  write("rgb/1.033333.png", pngBytes(colour(kWidth + 2, kHeight)));
  expectMentions(loadFrame(1), file("rgb/1.033333.png"), "size 10x6, camera expects 8x6");
  write("depth/1.005000.png", pngBytes(depth(kWidth, kHeight - 1)));
  expectMentions(loadFrame(0), file("depth/1.005000.png"), "size 8x5");
}

TEST_F(BadDataset, NextReportsTheErrorAndMovesOn) {
  write("rgb/1.000000.png", "garbage");
  std::unique_ptr<TumDatasetSource> source;
  ASSERT_TRUE(open(&source).ok());
  RgbdImage frame;
  EXPECT_EQ(source->next(frame), SourceResult::kError);
  expectMentions(source->lastError(), file("rgb/1.000000.png"));
  EXPECT_EQ(source->next(frame), SourceResult::kFrame);
  EXPECT_TRUE(source->lastError().ok());
}

TEST_F(BadDataset, EmptyList) {
  write("rgb.txt", "# color images\n# timestamp filename\n\n");
  std::unique_ptr<TumDatasetSource> source;
  expectMentions(open(&source), file("rgb.txt"), "empty list");
  write("rgb.txt", "");
  expectMentions(open(&source), file("rgb.txt"), "empty list");
}

TEST_F(BadDataset, UnparsableListLine) {
  write("depth.txt", "# depth\n1.005000 depth/1.005000.png\n1.O38000 depth/1.038000.png\n");
  std::unique_ptr<TumDatasetSource> source;
  expectMentions(open(&source), file("depth.txt") + ":3", "not a timestamp");
  write("depth.txt", "1.005000 depth/1.005000.png extra\n");
  expectMentions(open(&source), file("depth.txt") + ":1", "got 3 fields");
}

TEST_F(BadDataset, NonMonotonicTimestamps) {
  write("rgb.txt", "1.033333 rgb/1.033333.png\n1.000000 rgb/1.000000.png\n");
  std::unique_ptr<TumDatasetSource> source;
  expectMentions(open(&source), file("rgb.txt") + ":2", "non-monotonic");
}

TEST_F(BadDataset, DuplicateTimestamps) {
  write("depth.txt", "1.005000 depth/1.005000.png\n# gap\n1.005000 depth/1.038000.png\n");
  std::unique_ptr<TumDatasetSource> source;
  expectMentions(open(&source), file("depth.txt") + ":3", "duplicate");
}

TEST_F(BadDataset, MissingListFile) {
  std::filesystem::remove(file("depth.txt"));
  std::unique_ptr<TumDatasetSource> source;
  expectMentions(open(&source), file("depth.txt"), "cannot open");
}

TEST_F(BadDataset, NoPairWithinTheAssociationWindow) {
  write("depth.txt", "5.0 depth/1.005000.png\n6.0 depth/1.038000.png\n");
  std::unique_ptr<TumDatasetSource> source;
  expectMentions(open(&source), root(), "0.02 s");
}

TEST_F(BadDataset, BadAssociationsFile) {
  std::unique_ptr<TumDatasetSource> source;
  write("associations.txt", "1.000000 rgb/1.000000.png 1.005000\n");
  expectMentions(open(&source), file("associations.txt") + ":1", "got 3 fields");
  write("associations.txt",
        "1.033333 rgb/1.033333.png 1.038000 depth/1.038000.png\n"
        "1.000000 rgb/1.000000.png 1.005000 depth/1.005000.png\n");
  expectMentions(open(&source), file("associations.txt") + ":2", "non-monotonic rgb");
  write("associations.txt",
        "1.000000 rgb/1.000000.png 1.005000 depth/1.005000.png\n"
        "1.033333 rgb/1.033333.png 1.005000 depth/1.005000.png\n");
  expectMentions(open(&source), file("associations.txt") + ":2", "duplicate depth");
  write("associations.txt", "# nothing\n");
  expectMentions(open(&source), file("associations.txt"), "empty list");
  write("associations.txt", "nan rgb/1.000000.png 1.005000 depth/1.005000.png\n");
  expectMentions(open(&source), file("associations.txt") + ":1", "not a finite");
}

TEST_F(BadDataset, NotADatasetFolderOrBadCamera) {
  std::unique_ptr<TumDatasetSource> source;
  expectMentions(TumDatasetSource::open(file("nope"), tinyCamera(), &source), file("nope"),
                 "not a TUM RGB-D folder");
  PinholeCamera zero_focal = tinyCamera();
  zero_focal.fx = 0;
  expectMentions(TumDatasetSource::open(root(), zero_focal, &source), root(), "focal length");
}

TEST_F(BadDataset, OpenSourceUsesTheFolderCameraFileAndReportsItsErrors) {
  write("camera.txt", "fx 10\nfy -10\ncx 3.5\ncy 2.5\nwidth 8\nheight 6\n");
  std::unique_ptr<FrameSource> source;
  Status st = openFrameSource(root(), "", &source);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_EQ(source->camera().fy, -10);
  RgbdImage frame;
  EXPECT_EQ(source->next(frame), SourceResult::kFrame);

  write("camera.txt", "fx 10\nfy nan\ncx 3.5\ncy 2.5\n");
  expectMentions(openFrameSource(root(), "", &source), file("camera.txt") + ":2", "not finite");
  std::filesystem::remove(file("camera.txt"));
  // A temp folder's name says nothing about the sensor: refuse to guess intrinsics.
  expectMentions(openFrameSource(root(), "", &source), root(), "pass a camera");
  expectMentions(openFrameSource(root(), "tum7", &source), "tum7");
}

}  // namespace
}  // namespace plumb

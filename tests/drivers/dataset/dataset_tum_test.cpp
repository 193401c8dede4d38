// TUM replay on the shared real frames: counts, sizes, timestamps, depth factor, association.
#include <gtest/gtest.h>

#include <filesystem>

#include "tests/drivers/dataset_test_support.h"
#include "drivers/open/open_source.h"
#include "drivers/dataset/camera_presets.h"
#include "drivers/dataset/tum_dataset.h"
#include "drivers/dataset/tum_lists.h"

namespace plumb {
namespace {

PinholeCamera tum1() {
  PinholeCamera camera;
  EXPECT_TRUE(cameraPreset("tum1", &camera).ok());
  return camera;
}

// Depth readings of a desk scene seen by a Kinect: mostly valid, 0.3 .. 10 m.
void expectPlausibleKinectDepth(const RgbdImage& frame) {
  int valid = 0;
  double sum_m = 0;
  for (int v = 0; v < frame.depth_raw.rows; v += 4) {
    for (int u = 0; u < frame.depth_raw.cols; u += 4) {
      const uint16_t raw = frame.depth_raw.at<uint16_t>(v, u);
      if (raw == 0) continue;
      ++valid;
      sum_m += raw / frame.depth_factor;
    }
  }
  const int samples = (frame.depth_raw.rows / 4) * (frame.depth_raw.cols / 4);
  EXPECT_GT(valid, samples / 2);
  const double mean_m = sum_m / std::max(valid, 1);
  EXPECT_GT(mean_m, 0.3);
  EXPECT_LT(mean_m, 10.0);
}

TEST(TumDataset, Fr1DeskFirst9LoadsEveryFrame) {
  PLUMB_SKIP_WITHOUT_DATASET(dir, "tum_fr1_desk_first9");
  std::unique_ptr<TumDatasetSource> source;
  const Status st = TumDatasetSource::open(dir, tum1(), &source);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_TRUE(source->usedAssociationsFile());
  ASSERT_EQ(source->size(), 9u);
  EXPECT_DOUBLE_EQ(source->timestamp(0), 1305031453.359684);

  RgbdImage frame;
  int frames = 0;
  double previous_stamp = 0;
  SourceResult result;
  while ((result = source->next(frame)) == SourceResult::kFrame) {
    EXPECT_EQ(frame.sequence, static_cast<uint64_t>(frames));
    EXPECT_EQ(frame.bgr.type(), CV_8UC3);
    EXPECT_EQ(frame.depth_raw.type(), CV_16UC1);
    EXPECT_EQ(frame.bgr.cols, 640);
    EXPECT_EQ(frame.bgr.rows, 480);
    EXPECT_EQ(frame.depth_raw.size(), frame.bgr.size());
    EXPECT_DOUBLE_EQ(frame.depth_factor, 5000.0);
    EXPECT_GT(frame.timestamp_s, previous_stamp);
    EXPECT_LT(std::abs(frame.depth_timestamp_s - frame.timestamp_s), 0.02);
    previous_stamp = frame.timestamp_s;
    ++frames;
  }
  EXPECT_EQ(result, SourceResult::kEndOfStream);
  EXPECT_EQ(frames, 9);
  EXPECT_DOUBLE_EQ(previous_stamp, source->timestamp(8));
  expectPlausibleKinectDepth(frame);
}

TEST(TumDataset, Fr1RpyHead250LoadsAndRandomAccessMatchesReplay) {
  PLUMB_SKIP_WITHOUT_DATASET(dir, "tum_fr1_rpy_head250");
  std::unique_ptr<FrameSource> generic;
  // Through the generic opener: the folder name says freiburg 1, so tum1 is chosen.
  const Status st = openFrameSource(dir, "", &generic);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_DOUBLE_EQ(generic->camera().fx, 517.306408);

  std::unique_ptr<TumDatasetSource> source;
  ASSERT_TRUE(TumDatasetSource::open(dir, tum1(), &source).ok());
  ASSERT_EQ(source->size(), 250u);
  // ~8.3 s of a 30 Hz stream.
  const double span_s = source->timestamp(249) - source->timestamp(0);
  EXPECT_GT(span_s, 8.0);
  EXPECT_LT(span_s, 8.7);

  RgbdImage replayed, random_access;
  int frames = 0;
  while (generic->next(replayed) == SourceResult::kFrame) {
    // Spot-check random access against the replayed frame every 50 frames.
    if (frames % 50 == 0) {
      ASSERT_TRUE(source->load(frames, random_access).ok());
      EXPECT_EQ(random_access.timestamp_s, replayed.timestamp_s);
      EXPECT_EQ(cv::norm(random_access.bgr, replayed.bgr, cv::NORM_L1), 0.0);
      EXPECT_EQ(cv::norm(random_access.depth_raw, replayed.depth_raw, cv::NORM_L1), 0.0);
    }
    ++frames;
  }
  EXPECT_EQ(frames, 250);
  EXPECT_TRUE(generic->lastError().ok());
  expectPlausibleKinectDepth(replayed);
}

TEST(TumDataset, ReplayReusesTheCallersBuffers) {
  PLUMB_SKIP_WITHOUT_DATASET(dir, "tum_fr1_desk_first9");
  std::unique_ptr<TumDatasetSource> source;
  ASSERT_TRUE(TumDatasetSource::open(dir, tum1(), &source).ok());
  RgbdImage frame;
  ASSERT_EQ(source->next(frame), SourceResult::kFrame);
  const uchar* bgr_data = frame.bgr.data;
  const uchar* depth_data = frame.depth_raw.data;
  ASSERT_EQ(source->next(frame), SourceResult::kFrame);
  EXPECT_EQ(frame.bgr.data, bgr_data);
  EXPECT_EQ(frame.depth_raw.data, depth_data);
}

// Pairing rgb.txt with depth.txt by the benchmark's rule must give the shipped associations.txt.
TEST(TumDataset, AssociationWithoutAssociationsFileReproducesTheShippedOne) {
  for (const char* name : {"tum_fr1_desk_first9", "tum_fr1_rpy_head250"}) {
    const std::string dir = testing::sharedDataset(name);
    if (dir.empty()) GTEST_SKIP() << "shared dataset " << name << " not found under " PLUMB_DATASETS_DIR;
    std::vector<TumListEntry> rgb, depth;
    ASSERT_TRUE(readTumImageList(dir + "/rgb.txt", &rgb).ok());
    ASSERT_TRUE(readTumImageList(dir + "/depth.txt", &depth).ok());
    std::vector<TumFrameEntry> shipped;
    ASSERT_TRUE(readTumAssociations(dir + "/associations.txt", &shipped).ok());
    const std::vector<TumFrameEntry> ours = associateTumLists(rgb, depth);
    ASSERT_EQ(ours.size(), shipped.size()) << name;
    for (std::size_t i = 0; i < ours.size(); ++i) {
      EXPECT_EQ(ours[i].rgb_timestamp_s, shipped[i].rgb_timestamp_s) << name << " pair " << i;
      EXPECT_EQ(ours[i].depth_timestamp_s, shipped[i].depth_timestamp_s) << name << " pair " << i;
      EXPECT_EQ(ours[i].rgb_path, shipped[i].rgb_path);
      EXPECT_EQ(ours[i].depth_path, shipped[i].depth_path);
    }
  }
}

// The same folder without associations.txt opens and associates on its own.
TEST(TumDataset, OpensAFolderWithoutAssociationsFile) {
  PLUMB_SKIP_WITHOUT_DATASET(dir, "tum_fr1_desk_first9");
  testing::TempDir copy;
  namespace fs = std::filesystem;
  fs::create_directory_symlink(dir + "/rgb", copy.file("rgb"));
  fs::create_directory_symlink(dir + "/depth", copy.file("depth"));
  fs::copy_file(dir + "/rgb.txt", copy.file("rgb.txt"));
  fs::copy_file(dir + "/depth.txt", copy.file("depth.txt"));
  std::unique_ptr<TumDatasetSource> source, reference;
  const Status st = TumDatasetSource::open(copy.path(), tum1(), &source);
  ASSERT_TRUE(st.ok()) << st.message();
  ASSERT_TRUE(TumDatasetSource::open(dir, tum1(), &reference).ok());
  EXPECT_FALSE(source->usedAssociationsFile());
  ASSERT_EQ(source->size(), reference->size());
  for (std::size_t i = 0; i < source->size(); ++i)
    EXPECT_EQ(source->entry(i).depth_path, reference->entry(i).depth_path);
  RgbdImage frame;
  EXPECT_TRUE(source->load(source->size() - 1, frame).ok());
}

}  // namespace
}  // namespace plumb

// Synthetic ground truth is consistent with the images: frame A's depth, back-projected and moved
// into frame B with the ground-truth poses, lands on B's depth and colour.
//
// Tolerance (noise-free renders): among A's pixels that land inside B on the same surface
// (B's depth not nearer by more than 5 cm: otherwise occluded in B) and away from depth edges,
//   >= 98% agree with B's depth within 1 cm (B's inverse depth interpolated bilinearly, which is
//   exact on a plane), and
//   >= 95% agree with B's colour within 12 grey levels (mean over channels; texture resampling
//   at a different scale and angle is the only difference).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include <unistd.h>

#include <opencv2/core.hpp>

#include "drivers/dataset/camera_file.h"
#include "drivers/dataset/tum_dataset.h"
#include "drivers/synth/synthetic_scene.h"
#include "drivers/trajectory/trajectory_io.h"

namespace plumb {
namespace {

struct Agreement {
  int compared = 0;
  int depth_within_1cm = 0;
  int colour_within_12 = 0;
  double depthFraction() const { return compared ? static_cast<double>(depth_within_1cm) / compared : 0; }
  double colourFraction() const { return compared ? static_cast<double>(colour_within_12) / compared : 0; }
};

// Bilinear inverse depth at (u, v) if the four neighbours are valid and on one surface.
bool interpolateDepth(const cv::Mat& depth_raw, double factor, double u, double v, double* z) {
  const int x0 = static_cast<int>(std::floor(u)), y0 = static_cast<int>(std::floor(v));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= depth_raw.cols || y0 + 1 >= depth_raw.rows) return false;
  double inv[4], lo = 1e9, hi = 0;
  for (int k = 0; k < 4; ++k) {
    const uint16_t raw = depth_raw.at<uint16_t>(y0 + k / 2, x0 + k % 2);
    if (raw == 0) return false;
    const double metres = raw / factor;
    lo = std::min(lo, metres);
    hi = std::max(hi, metres);
    inv[k] = 1.0 / metres;
  }
  if (hi - lo > 0.05 + 0.02 * hi) return false;  // a depth edge: not one surface
  const double ax = u - x0, ay = v - y0;
  const double top = inv[0] + ax * (inv[1] - inv[0]), bottom = inv[2] + ax * (inv[3] - inv[2]);
  *z = 1.0 / (top + ay * (bottom - top));
  return true;
}

cv::Vec3d interpolateColour(const cv::Mat& bgr, double u, double v) {
  const int x0 = static_cast<int>(std::floor(u)), y0 = static_cast<int>(std::floor(v));
  const double ax = u - x0, ay = v - y0;
  cv::Vec3d result;
  for (int k = 0; k < 3; ++k) {
    const double top = bgr.at<cv::Vec3b>(y0, x0)[k] * (1 - ax) + bgr.at<cv::Vec3b>(y0, x0 + 1)[k] * ax;
    const double bottom = bgr.at<cv::Vec3b>(y0 + 1, x0)[k] * (1 - ax) + bgr.at<cv::Vec3b>(y0 + 1, x0 + 1)[k] * ax;
    result[k] = top * (1 - ay) + bottom * ay;
  }
  return result;
}

Agreement reproject(const PinholeCamera& camera, const RgbdImage& a, const Eigen::Isometry3d& T_world_a,
                    const RgbdImage& b, const Eigen::Isometry3d& T_world_b) {
  const Eigen::Isometry3d T_b_a = T_world_b.inverse() * T_world_a;
  Agreement agreement;
  for (int y = 0; y < a.depth_raw.rows; y += 2) {
    for (int x = 0; x < a.depth_raw.cols; x += 2) {
      double z_a = 0;
      if (!interpolateDepth(a.depth_raw, a.depth_factor, x, y, &z_a)) continue;  // skips A's edges
      const Eigen::Vector3d P_b = T_b_a * camera.unproject(x, y, z_a);
      if (P_b.z() <= 0.1) continue;
      const Eigen::Vector2d uv_b = camera.project(P_b);
      double z_b = 0;
      if (!interpolateDepth(b.depth_raw, b.depth_factor, uv_b.x(), uv_b.y(), &z_b)) continue;
      if (z_b < P_b.z() - 0.05) continue;  // occluded in B
      ++agreement.compared;
      if (std::abs(z_b - P_b.z()) < 0.01) ++agreement.depth_within_1cm;
      const cv::Vec3b colour_a = a.bgr.at<cv::Vec3b>(y, x);
      const cv::Vec3d colour_b = interpolateColour(b.bgr, uv_b.x(), uv_b.y());
      const double difference = (std::abs(colour_a[0] - colour_b[0]) + std::abs(colour_a[1] - colour_b[1]) +
                                 std::abs(colour_a[2] - colour_b[2])) / 3;
      if (difference <= 12) ++agreement.colour_within_12;
    }
  }
  return agreement;
}

void expectConsistent(const Agreement& agreement) {
  std::printf("reprojection: %d pixels, depth within 1 cm %.4f, colour within 12 %.4f\n", agreement.compared,
              agreement.depthFraction(), agreement.colourFraction());
  EXPECT_GT(agreement.compared, 20000) << "too little overlap to judge";
  EXPECT_GE(agreement.depthFraction(), 0.98) << agreement.depth_within_1cm << " of " << agreement.compared;
  EXPECT_GE(agreement.colourFraction(), 0.95) << agreement.colour_within_12 << " of " << agreement.compared;
}

TEST(SynthReprojection, DepthAndColourAgreeAcrossFramesInMemory) {
  for (const char* preset : {"textured", "low_texture", "fast_rotation"}) {
    SynthOptions options;
    options.preset = preset;
    options.seed = 11;
    std::unique_ptr<SyntheticScene> scene;
    ASSERT_TRUE(SyntheticScene::create(options, &scene).ok());
    for (const auto& [i, j] : {std::pair{0, 5}, std::pair{120, 135}, std::pair{250, 260}}) {
      SCOPED_TRACE(std::string(preset) + " frames " + std::to_string(i) + "->" + std::to_string(j));
      RgbdImage a, b;
      ASSERT_TRUE(scene->render(i, a).ok());
      ASSERT_TRUE(scene->render(j, b).ok());
      expectConsistent(reproject(scene->camera(), a, scene->T_world_cam(i), b, scene->T_world_cam(j)));
    }
  }
}

TEST(SynthReprojection, WrongPoseIsDetected) {
  // The check must be able to fail: a 3 cm error in B's pose breaks depth agreement.
  SynthOptions options;
  options.preset = "low_texture";
  std::unique_ptr<SyntheticScene> scene;
  ASSERT_TRUE(SyntheticScene::create(options, &scene).ok());
  RgbdImage a, b;
  ASSERT_TRUE(scene->render(0, a).ok());
  ASSERT_TRUE(scene->render(5, b).ok());
  Eigen::Isometry3d T_world_b_wrong = scene->T_world_cam(5);
  T_world_b_wrong.translation() += Eigen::Vector3d(0.03, 0, 0.0);
  const Agreement agreement = reproject(scene->camera(), a, scene->T_world_cam(0), b, T_world_b_wrong);
  std::printf("wrong pose: depth within 1 cm %.4f\n", agreement.depthFraction());
  EXPECT_LT(agreement.depthFraction(), 0.8);
}

TEST(SynthReprojection, WrittenDatasetReadBackMatches) {
  // The acceptance check on files: write low_texture seed 7, read it back with the TUM reader,
  // the ground truth and camera files, and reproject frame 0 into 6 and 3 into 9.
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("plumb_synth_reproj_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  SynthOptions options;
  options.preset = "low_texture";
  options.seed = 7;
  options.frames = 10;
  ASSERT_TRUE(writeSynthDataset(options, dir.string()).ok());

  PinholeCamera camera;
  ASSERT_TRUE(readCameraFile((dir / "camera.txt").string(), &camera).ok());
  std::vector<StampedPose> ground_truth;
  ASSERT_TRUE(readTumTrajectory((dir / "groundtruth.txt").string(), &ground_truth).ok());
  ASSERT_EQ(ground_truth.size(), 10u);
  std::unique_ptr<TumDatasetSource> dataset;
  const Status opened = TumDatasetSource::open(dir.string(), camera, &dataset);
  ASSERT_TRUE(opened.ok()) << opened.message();
  ASSERT_EQ(dataset->size(), 10u);
  EXPECT_TRUE(dataset->usedAssociationsFile());
  for (const auto& [i, j] : {std::pair{0, 6}, std::pair{3, 9}}) {
    RgbdImage a, b;
    ASSERT_TRUE(dataset->load(i, a).ok());
    ASSERT_TRUE(dataset->load(j, b).ok());
    ASSERT_DOUBLE_EQ(dataset->timestamp(i), ground_truth[i].timestamp);
    expectConsistent(reproject(camera, a, ground_truth[i].T_world_cam, b, ground_truth[j].T_world_cam));
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace plumb

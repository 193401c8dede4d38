// writeSynthDataset: a synthetic scene written in TUM RGB-D layout (see synthetic_scene.h).
#include <cstdio>
#include <filesystem>
#include <system_error>
#include <vector>


#include "drivers/dataset/camera_file.h"
#include "drivers/image/png_encoder.h"
#include "drivers/synth/synthetic_scene.h"
#include "drivers/trajectory/trajectory_io.h"

namespace plumb {
namespace {

std::string formatStamp(double t) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.6f", t);
  return text;
}

Status makeDirectory(const std::filesystem::path& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) return Status::Error(dir.string() + ": cannot create directory (" + error.message() + ")");
  if (!std::filesystem::is_directory(dir)) return Status::Error(dir.string() + ": exists and is not a directory");
  return Status::Ok();
}

// A text file assembled in memory and written in one go, so a failure is reported once.
Status writeTextFile(const std::filesystem::path& path, const std::string& text) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) return Status::Error(path.string() + ": cannot write");
  const bool ok = std::fwrite(text.data(), 1, text.size(), file) == text.size();
  if (std::fclose(file) != 0 || !ok) return Status::Error(path.string() + ": write failed");
  return Status::Ok();
}

Status writePng(const std::filesystem::path& path, const cv::Mat& image) {
  // The settings of cv::imwrite without parameters, which wrote these files before.
  return writePngFile(path.string(), image, pngFastestOptions());
}

}  // namespace

Status writeSynthDataset(const SynthOptions& options, const std::string& out_dir) {
  std::unique_ptr<SyntheticScene> scene;
  PLUMB_RETURN_IF_ERROR(SyntheticScene::create(options, &scene));
  const std::filesystem::path root(out_dir);
  PLUMB_RETURN_IF_ERROR(makeDirectory(root / "rgb"));
  PLUMB_RETURN_IF_ERROR(makeDirectory(root / "depth"));

  const std::string header = "# plumb synthetic scene: preset " + options.preset + ", seed " +
                             std::to_string(options.seed) + ", " + std::to_string(options.frames) + " frames\n";
  std::string rgb_list = header + "# timestamp filename\n";
  std::string depth_list = rgb_list;
  std::string associations = header + "# rgb_timestamp rgb_file depth_timestamp depth_file\n";
  std::vector<StampedPose> ground_truth;
  ground_truth.reserve(options.frames);

  RgbdImage frame;
  for (int i = 0; i < scene->numFrames(); ++i) {
    PLUMB_RETURN_IF_ERROR(scene->render(i, frame));
    const std::string stamp = formatStamp(scene->timestamp(i));
    const std::string rgb_file = "rgb/" + stamp + ".png", depth_file = "depth/" + stamp + ".png";
    PLUMB_RETURN_IF_ERROR(writePng(root / rgb_file, frame.bgr));
    PLUMB_RETURN_IF_ERROR(writePng(root / depth_file, frame.depth_raw));
    rgb_list += stamp + " " + rgb_file + "\n";
    depth_list += stamp + " " + depth_file + "\n";
    associations += stamp + " " + rgb_file + " " + stamp + " " + depth_file + "\n";
    StampedPose pose;
    pose.timestamp = scene->timestamp(i);  // printed "%.6f" like the stamps above
    pose.T_world_cam = scene->T_world_cam(i);
    ground_truth.push_back(pose);
  }
  PLUMB_RETURN_IF_ERROR(writeTextFile(root / "rgb.txt", rgb_list));
  PLUMB_RETURN_IF_ERROR(writeTextFile(root / "depth.txt", depth_list));
  PLUMB_RETURN_IF_ERROR(writeTextFile(root / "associations.txt", associations));
  PLUMB_RETURN_IF_ERROR(writeTumTrajectory((root / "groundtruth.txt").string(), ground_truth));
  PLUMB_RETURN_IF_ERROR(writeCameraFile((root / "camera.txt").string(), scene->camera()));
  return Status::Ok();
}

}  // namespace plumb

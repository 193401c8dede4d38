#include "drivers/dataset/tum_dataset.h"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "drivers/dataset/tum_lists.h"

namespace plumb {
namespace {

bool fileExists(const std::string& path) { return std::ifstream(path).good(); }

std::string typeName(const cv::Mat& m) {
  const int depth = m.depth();
  const char* depth_name = depth == CV_8U    ? "8-bit"
                           : depth == CV_16U ? "16-bit"
                           : depth == CV_8S  ? "8-bit signed"
                           : depth == CV_16S ? "16-bit signed"
                           : depth == CV_32F ? "32-bit float"
                                             : "other-depth";
  return std::string(depth_name) + " " + std::to_string(m.channels()) + "-channel";
}

int64_t monotonicNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Reads the whole file into `bytes`, reusing its capacity from frame to frame.
Status readFileBytes(const std::string& path, std::vector<unsigned char>* bytes) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) return Status::Error(path + ": missing or unreadable image file");
  bytes->clear();
  unsigned char chunk[65536];
  std::size_t n = 0;
  while ((n = std::fread(chunk, 1, sizeof(chunk), file)) > 0) bytes->insert(bytes->end(), chunk, chunk + n);
  const bool failed = std::ferror(file) != 0;
  std::fclose(file);
  if (failed) return Status::Error(path + ": read error");
  if (bytes->empty()) return Status::Error(path + ": empty image file");
  return Status::Ok();
}

}  // namespace

Status TumDatasetSource::open(const std::string& dir, const PinholeCamera& camera,
                              std::unique_ptr<TumDatasetSource>* out) {
  const std::string problem = camera.validate();
  if (!problem.empty()) return Status::Error("camera for " + dir + ": " + problem);
  std::unique_ptr<TumDatasetSource> source(new TumDatasetSource());
  source->dir_ = dir;
  source->camera_ = camera;
  const std::string associations = dir + "/associations.txt";
  if (fileExists(associations)) {
    PLUMB_RETURN_IF_ERROR(readTumAssociations(associations, &source->frames_));
    source->used_associations_file_ = true;
  } else {
    const std::string rgb_list = dir + "/rgb.txt", depth_list = dir + "/depth.txt";
    if (!fileExists(rgb_list) && !fileExists(depth_list))
      return Status::Error(dir + ": not a TUM RGB-D folder (no associations.txt, rgb.txt, depth.txt)");
    std::vector<TumListEntry> rgb, depth;
    PLUMB_RETURN_IF_ERROR(readTumImageList(rgb_list, &rgb));
    PLUMB_RETURN_IF_ERROR(readTumImageList(depth_list, &depth));
    source->frames_ = associateTumLists(rgb, depth);
    if (source->frames_.empty())
      return Status::Error(dir + ": no rgb.txt/depth.txt pair within 0.02 s of each other");
  }
  // Fail fast: a missing image is reported at open, not minutes into a run.
  const std::string lists = source->used_associations_file_ ? "associations.txt" : "rgb.txt/depth.txt";
  for (const TumFrameEntry& frame : source->frames_) {
    for (const std::string* relative : {&frame.rgb_path, &frame.depth_path}) {
      if (!fileExists(dir + "/" + *relative))
        return Status::Error(dir + "/" + *relative + ": missing image file (listed in " + lists + ")");
    }
  }
  *out = std::move(source);
  return Status::Ok();
}

Status TumDatasetSource::loadImage(const std::string& relative_path, bool is_depth, cv::Mat& dst) {
  const std::string path = dir_ + "/" + relative_path;
  PLUMB_RETURN_IF_ERROR(readFileBytes(path, &file_bytes_));
  // IMREAD_UNCHANGED keeps the stored bit depth so an 8-bit depth map is caught, not converted.
  // Decoding into `dst` reuses its buffer when size and type match (every frame after the first).
  try {
    cv::imdecode(file_bytes_, cv::IMREAD_UNCHANGED, &dst);
  } catch (const cv::Exception& e) {
    return Status::Error(path + ": cannot decode image (" + e.what() + ")");
  }
  if (dst.empty()) return Status::Error(path + ": corrupt, truncated or not an image");
  const int expected_type = is_depth ? CV_16UC1 : CV_8UC3;
  if (dst.type() != expected_type)
    return Status::Error(path + ": " + typeName(dst) + " image, expected " +
                         (is_depth ? "16-bit 1-channel depth" : "8-bit 3-channel colour"));
  if (dst.cols != camera_.width || dst.rows != camera_.height)
    return Status::Error(path + ": size " + std::to_string(dst.cols) + "x" + std::to_string(dst.rows) +
                         ", camera expects " + std::to_string(camera_.width) + "x" +
                         std::to_string(camera_.height));
  return Status::Ok();
}

Status TumDatasetSource::load(std::size_t i, RgbdImage& out) {
  if (i >= frames_.size())
    return Status::Error(describe() + ": frame " + std::to_string(i) + " out of range (" +
                         std::to_string(frames_.size()) + " frames)");
  const TumFrameEntry& frame = frames_[i];
  PLUMB_RETURN_IF_ERROR(loadImage(frame.rgb_path, false, out.bgr));
  PLUMB_RETURN_IF_ERROR(loadImage(frame.depth_path, true, out.depth_raw));
  out.sequence = i;
  out.timestamp_s = frame.rgb_timestamp_s;
  out.depth_timestamp_s = frame.depth_timestamp_s;
  out.depth_factor = camera_.depth_factor;
  out.t_sensor_ns = monotonicNowNs();
  return Status::Ok();
}

SourceResult TumDatasetSource::next(RgbdImage& out) {
  if (cursor_ >= frames_.size()) return SourceResult::kEndOfStream;
  // The cursor moves past a bad frame too, so a caller that chooses to skip it can continue.
  last_error_ = load(cursor_++, out);
  return last_error_.ok() ? SourceResult::kFrame : SourceResult::kError;
}

}  // namespace plumb

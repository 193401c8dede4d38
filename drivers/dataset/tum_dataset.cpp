#include "drivers/dataset/tum_dataset.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "drivers/dataset/png_decoder.h"
#include "drivers/dataset/tum_lists.h"
#include "drivers/image/jpeg_decoder.h"
#include "platform/input_file.h"

namespace plumb {
namespace {

// stat(), never open(): a FIFO named like a list must not block the open (platform/input_file.h).
bool fileExists(const std::string& path) { return pathKind(path) != PathKind::kMissing; }

std::string typeName(int type) {
  const int depth = CV_MAT_DEPTH(type);
  const char* depth_name = depth == CV_8U    ? "8-bit"
                           : depth == CV_16U ? "16-bit"
                           : depth == CV_8S  ? "8-bit signed"
                           : depth == CV_16S ? "16-bit signed"
                           : depth == CV_32F ? "32-bit float"
                                             : "other-depth";
  return std::string(depth_name) + " " + std::to_string(CV_MAT_CN(type)) + "-channel";
}

// The checks every image passes whichever decoder read it; "" when it fits.
std::string imageProblem(int type, int width, int height, bool is_depth, const PinholeCamera& camera) {
  const int expected_type = is_depth ? CV_16UC1 : CV_8UC3;
  if (type != expected_type)
    return typeName(type) + " image, expected " + (is_depth ? "16-bit 1-channel depth" : "8-bit 3-channel colour");
  // Depth from an unregistered depth camera has that camera's size (registered later, in the pipeline).
  const int expected_width = is_depth ? camera.depthWidth() : camera.width;
  const int expected_height = is_depth ? camera.depthHeight() : camera.height;
  if (width != expected_width || height != expected_height)
    return "size " + std::to_string(width) + "x" + std::to_string(height) + ", " +
           (is_depth && !camera.depthRegistered() ? "depth camera" : "camera") + " expects " +
           std::to_string(expected_width) + "x" + std::to_string(expected_height);
  return "";
}

// An image file larger than this is not a frame of an 8192-pixel camera (16-bit, uncompressed,
// with room for a PNG's worst-case overhead).
constexpr uint64_t kMaxImageFileBytes = uint64_t(kMaxImageSide) * kMaxImageSide * 4;

int64_t monotonicNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Reads the whole file into `bytes` (grown only when a file is larger than any before: no
// allocation per frame; POSIX read, because stdio's FILE allocates its buffer on every fopen).
// `file` is the caller's, reused frame after frame: its path string keeps its capacity, so opening
// the next image allocates nothing (a fresh opener per image cost two allocations a frame).
Status readFileBytes(const std::string& path, InputFile& file, std::unique_ptr<unsigned char[]>* bytes,
                     std::size_t* capacity, std::size_t* size) {
  PLUMB_RETURN_IF_ERROR(file.open(path, kMaxImageFileBytes, "image file"));
  const int fd = file.fd();
  const auto expected = static_cast<std::size_t>(file.size());
  // 50 % headroom: file sizes vary from frame to frame; growing to exactly the largest so far
  // would reallocate whenever a later frame beats it.
  if (*capacity < expected) {
    *capacity = expected + expected / 2;
    bytes->reset(new unsigned char[*capacity]);  // contents need not survive: read anew below
  }
  std::size_t got = 0;
  bool failed = false;
  while (got < expected) {
    const ssize_t n = ::read(fd, bytes->get() + got, expected - got);
    if (n < 0 && errno == EINTR) continue;
    failed = n < 0;
    if (n <= 0) break;  // error, or the file shrank meanwhile (a truncated image: the decoder says so)
    got += static_cast<std::size_t>(n);
  }
  file.close();
  if (failed) return Status::Error(path + ": read error");
  if (got == 0) return Status::Error(path + ": empty image file");
  *size = got;
  return Status::Ok();
}

}  // namespace

TumDatasetSource::TumDatasetSource() = default;
TumDatasetSource::~TumDatasetSource() = default;

Status TumDatasetSource::open(const std::string& dir, const PinholeCamera& camera,
                              std::unique_ptr<TumDatasetSource>* out, std::size_t max_frames) {
  const std::string problem = camera.validate();
  if (!problem.empty()) return Status::Error("camera for " + dir + ": " + problem);
  std::unique_ptr<TumDatasetSource> source(new TumDatasetSource());
  source->dir_ = dir;
  source->camera_ = camera;
  const std::string associations = dir + "/associations.txt";
  if (fileExists(associations)) {
    PLUMB_RETURN_IF_ERROR(readTumAssociations(associations, &source->frames_, max_frames));
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
    if (max_frames > 0 && source->frames_.size() > max_frames) source->frames_.resize(max_frames);
  }
  // Fail fast: a missing image is reported at open, not minutes into a run.
  const std::string lists = source->used_associations_file_ ? "associations.txt" : "rgb.txt/depth.txt";
  for (const TumFrameEntry& frame : source->frames_) {
    for (const std::string* relative : {&frame.rgb_path, &frame.depth_path}) {
      // Missing, a symlink loop, a FIFO: the reason, not a guess.
      const std::string path = dir + "/" + *relative;
      const Status present = requireRegularFile(path, "");
      if (!present.ok()) {
        if (pathKind(path) == PathKind::kMissing)
          return Status::Error(path + ": missing image file (listed in " + lists + ")");
        return Status::Error(present.message() + " (an image file listed in " + lists + ")");
      }
    }
    // Full paths once, so loading a frame builds no strings.
    source->rgb_files_.push_back(dir + "/" + frame.rgb_path);
    source->depth_files_.push_back(dir + "/" + frame.depth_path);
  }
  source->png_ = std::make_unique<PngDecoder>();
  // Buffers for the largest image file the camera's images can be (colour, or depth at the depth
  // camera's size), once: replaying then allocates nothing per frame, whatever the file sizes.
  const int width = std::max(camera.width, camera.depthWidth()), height = std::max(camera.height, camera.depthHeight());
  source->png_->reserve(width, height);
  source->file_capacity_ = pngFileBound(width, height, 3);
  source->file_bytes_.reset(new unsigned char[source->file_capacity_]);  // not zero-filled: address space only
  *out = std::move(source);
  return Status::Ok();
}

Status TumDatasetSource::loadImage(const std::string& path, bool is_depth, cv::Mat& dst) {
  std::size_t size = 0;
  PLUMB_RETURN_IF_ERROR(readFileBytes(path, image_file_, &file_bytes_, &file_capacity_, &size));
  PngHeader header;
  if (png_->readHeader(file_bytes_.get(), size, &header)) {
    // PNG (every TUM and ICL-NUIM image): libpng straight into dst, checked before decoding.
    const int type = CV_MAKETYPE(header.bit_depth == 16 ? CV_16U : CV_8U, header.channels);
    const std::string problem = imageProblem(type, header.width, header.height, is_depth, camera_);
    if (!problem.empty()) return Status::Error(path + ": " + problem);
    if (!png_->decodePixels(dst)) return Status::Error(path + ": " + png_->error());
    return Status::Ok();
  }
  if (size >= 8 && std::memcmp(file_bytes_.get(), "\x89PNG\r\n\x1a\n", 8) == 0) {
    return Status::Error(path + ": " + png_->error());  // a PNG libpng rejected
  }
  // A JPEG colour stream (some converted datasets store rgb/*.jpg): libjpeg, which allocates per
  // image. Grey JPEGs stay one channel so that a JPEG depth map is caught below, not converted.
  if (!looksLikeJpeg(file_bytes_.get(), size))
    return Status::Error(path + ": corrupt, truncated or not an image (plumb reads PNG and JPEG)");
  std::string error;
  if (!decodeJpeg(file_bytes_.get(), size, dst, &error)) return Status::Error(path + ": " + error);
  const std::string problem = imageProblem(dst.type(), dst.cols, dst.rows, is_depth, camera_);
  if (!problem.empty()) return Status::Error(path + ": " + problem);
  return Status::Ok();
}

Status TumDatasetSource::load(std::size_t i, RgbdImage& out) {
  if (i >= frames_.size())
    return Status::Error(describe() + ": frame " + std::to_string(i) + " out of range (" +
                         std::to_string(frames_.size()) + " frames)");
  const TumFrameEntry& frame = frames_[i];
  PLUMB_RETURN_IF_ERROR(loadImage(rgb_files_[i], false, out.bgr));
  PLUMB_RETURN_IF_ERROR(loadImage(depth_files_[i], true, out.depth_raw));
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

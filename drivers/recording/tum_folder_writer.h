#pragma once
// TumFolderWriter: writes frames as a folder in the TUM RGB-D layout, readable by
// TumDatasetSource and the benchmark's own scripts:
//   rgb/<t>.png  depth/<t>.png (16-bit)  rgb.txt  depth.txt  associations.txt  camera.txt
// Timestamps are written with the fewest decimals (6 at least, as the benchmark does) that read
// back as the identical double, so recording -> folder -> recording keeps them bit for bit.
#include <cstdio>
#include <memory>
#include <string>

#include "sensor/camera.h"
#include "sensor/rgbd_image.h"
#include "platform/status.h"

namespace plumb {

class TumFolderWriter {
 public:
  // Creates `dir` (and rgb/, depth/); fails if it already holds an rgb.txt (never overwrite data).
  static Status open(const std::string& dir, const PinholeCamera& camera,
                     std::unique_ptr<TumFolderWriter>* out);
  ~TumFolderWriter();
  Status append(const RgbdImage& frame);
  Status close();  // flushes the lists; idempotent
  uint64_t framesWritten() const { return frames_; }

 private:
  TumFolderWriter() = default;
  std::string dir_;
  std::FILE* rgb_list_ = nullptr;
  std::FILE* depth_list_ = nullptr;
  std::FILE* associations_ = nullptr;
  uint64_t frames_ = 0;
};

// "1305031102.175304": %.6f when that reads back exactly, else more digits.
std::string formatTimestamp(double t);

}  // namespace plumb

#pragma once
// PNG encoding with libpng directly: plots, TUM folders, synthetic datasets and recording frames.
//
// Why not cv::imwrite / cv::imencode: libopencv_imgcodecs pulls ~120 shared libraries (GDAL, HDF5,
// OpenEXR, ...) into every process that links it, for a format libpng writes on its own. The
// settings below reproduce what OpenCV 4's PNG encoder does with the same parameters (same
// filters, zlib level and strategy, no extra chunks), so the bytes match imencode's (a test checks).
//
// Accepted: CV_8U or CV_16U with 1 (grey), 3 (BGR) or 4 (BGRA) channels; 16-bit samples are
// written big-endian as PNG requires, whatever the host.
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "platform/status.h"

namespace plumb {

struct PngEncodeOptions {
  // zlib level 0..9. Default 1: lossless frames at a fraction of level 6's time.
  int compression_level = 1;
  // zlib's run-length strategy (Z_RLE) instead of the default: on camera frames both faster and
  // smaller at level 1 (what recordings use).
  bool rle_strategy = false;
  // Only the SUB row filter instead of libpng's adaptive choice: OpenCV's imwrite without
  // parameters does this (with level 1); plots use it.
  bool sub_filter_only = false;
};

// The settings of `cv::imwrite(path, image)` without parameters (OpenCV 4: SUB filter, level 1,
// run-length strategy).
inline PngEncodeOptions pngFastestOptions() {
  PngEncodeOptions options;
  options.sub_filter_only = true;
  options.rle_strategy = true;
  return options;
}

// Appends the PNG encoding of `image` to `out`. Error (nothing appended) for other Mat types.
Status encodePng(const cv::Mat& image, const PngEncodeOptions& options, std::vector<uint8_t>& out);

// Encodes `image` and writes it to `path` (replaced if present).
Status writePngFile(const std::string& path, const cv::Mat& image, const PngEncodeOptions& options);
// A command's output image (`eval --plot`, `profile --png`): written through AtomicFile
// (drivers/common/atomic_file.h), so it appears only when complete, through a symlink to its
// target. writePngFile above writes in place: for the many images of a new dataset folder.
Status writePngOutput(const std::string& path, const cv::Mat& image, const PngEncodeOptions& options);

}  // namespace plumb

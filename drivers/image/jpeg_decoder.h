#pragma once
// JPEG bytes -> BGR (or grey) cv::Mat with libjpeg(-turbo) directly: V4L2 MJPEG frames and JPEG
// colour images in TUM-layout folders.
//
// Why not cv::imdecode: libopencv_imgcodecs pulls ~120 shared libraries into the process. libjpeg
// is optional: without it (PLUMB_HAVE_LIBJPEG unset) jpegAvailable() is false and decodeJpeg()
// reports "built without libjpeg".
//
// libjpeg allocates its decompressor state per image (it has no reset that keeps the buffers), so
// JPEG input is not allocation-free; `dst` is reused when its size and type match.
#include <cstddef>
#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

namespace plumb {

bool jpegAvailable();

// True for bytes that start with the JPEG start-of-image marker FF D8 FF.
bool looksLikeJpeg(const uint8_t* bytes, std::size_t size);

// Decodes a baseline or progressive JPEG: 1-component images to CV_8UC1, others to CV_8UC3 (BGR).
// False with *error set on corrupt data or when built without libjpeg.
bool decodeJpeg(const uint8_t* bytes, std::size_t size, cv::Mat& dst, std::string* error);

}  // namespace plumb

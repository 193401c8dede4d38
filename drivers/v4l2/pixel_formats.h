#pragma once
// Conversions from V4L2 buffer layouts to plumb's frame images. Destinations are created once
// (same size every frame) and then reused, so steady-state conversion does not allocate, except
// MJPEG, whose decoder (libjpeg, drivers/image/jpeg_decoder.h) allocates internally. Without
// libjpeg at build time MJPEG frames are refused (mjpegToBgr returns false).
#include <cstddef>
#include <cstdint>

#include <opencv2/core.hpp>

namespace plumb {

// Packed YUYV 4:2:2 (Y0 U Y1 V per pixel pair), ITU-R BT.601 limited range (what UVC cameras
// send) -> BGR. `stride` is bytesperline. `width` must be even.
void yuyvToBgr(const uint8_t* src, int width, int height, std::size_t stride, cv::Mat& bgr);

// 8-bit grey -> BGR with B = G = R.
void greyToBgr(const uint8_t* src, int width, int height, std::size_t stride, cv::Mat& bgr);

// Z16: 16-bit little-endian depth units, copied unchanged (0 = no reading).
void z16ToDepth(const uint8_t* src, int width, int height, std::size_t stride, cv::Mat& depth_raw);

// One JPEG image (MJPEG frame) -> BGR. False when it is cut off (no end-of-image marker) or
// does not decode to width x height.
bool mjpegToBgr(const uint8_t* src, std::size_t size, int width, int height, cv::Mat& bgr);

}  // namespace plumb

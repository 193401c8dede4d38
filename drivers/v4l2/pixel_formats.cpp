#include "drivers/v4l2/pixel_formats.h"

#include <algorithm>

#include "drivers/image/jpeg_decoder.h"

namespace plumb {
namespace {

inline uint8_t clampByte(int v) { return static_cast<uint8_t>(std::clamp(v, 0, 255)); }

// BT.601 limited range in 8.8 fixed point: 298 = 255/219 * 256, 409 = 1.596 * 256, ...
inline void yuvToBgr(int y, int u, int v, uint8_t* bgr) {
  const int c = 298 * (y - 16) + 128, d = u - 128, e = v - 128;
  bgr[0] = clampByte((c + 516 * d) >> 8);
  bgr[1] = clampByte((c - 100 * d - 208 * e) >> 8);
  bgr[2] = clampByte((c + 409 * e) >> 8);
}

}  // namespace

void yuyvToBgr(const uint8_t* src, int width, int height, std::size_t stride, cv::Mat& bgr) {
  bgr.create(height, width, CV_8UC3);
  for (int r = 0; r < height; ++r) {
    const uint8_t* in = src + r * stride;
    uint8_t* out = bgr.ptr<uint8_t>(r);
    for (int c = 0; c + 1 < width; c += 2, in += 4, out += 6) {
      yuvToBgr(in[0], in[1], in[3], out);
      yuvToBgr(in[2], in[1], in[3], out + 3);
    }
  }
}

void greyToBgr(const uint8_t* src, int width, int height, std::size_t stride, cv::Mat& bgr) {
  bgr.create(height, width, CV_8UC3);
  for (int r = 0; r < height; ++r) {
    const uint8_t* in = src + r * stride;
    uint8_t* out = bgr.ptr<uint8_t>(r);
    for (int c = 0; c < width; ++c, out += 3) out[0] = out[1] = out[2] = in[c];
  }
}

void z16ToDepth(const uint8_t* src, int width, int height, std::size_t stride, cv::Mat& depth_raw) {
  depth_raw.create(height, width, CV_16UC1);
  for (int r = 0; r < height; ++r) {
    const uint8_t* in = src + r * stride;
    uint16_t* out = depth_raw.ptr<uint16_t>(r);
    for (int c = 0; c < width; ++c, in += 2) out[c] = static_cast<uint16_t>(in[0] | (in[1] << 8));
  }
}

bool mjpegToBgr(const uint8_t* src, std::size_t size, int width, int height, cv::Mat& bgr) {
  // libjpeg "decodes" a cut-off frame by padding it with grey; a complete JPEG ends with the EOI
  // marker FF D9 (UVC drivers may pad the buffer with zeros after it).
  std::size_t end = size;
  while (end > 0 && src[end - 1] == 0) --end;
  if (end < 4 || src[end - 2] != 0xFF || src[end - 1] != 0xD9) return false;
  if (!decodeJpeg(src, end, bgr, nullptr)) return false;
  return bgr.type() == CV_8UC3 && bgr.cols == width && bgr.rows == height;
}

}  // namespace plumb

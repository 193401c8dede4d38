#include "drivers/image/jpeg_decoder.h"

#include <cstdio>
#include <utility>

#if PLUMB_HAVE_LIBJPEG
#include "drivers/image/jpeg_errors.h"
#endif

namespace plumb {

bool looksLikeJpeg(const uint8_t* bytes, std::size_t size) {
  return size >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF;
}

#if PLUMB_HAVE_LIBJPEG

namespace {

// The libjpeg calls, apart so that setjmp's frame holds no objects with destructors. The Mat is
// created inside, after the header is known.
bool decodeRows(const uint8_t* bytes, std::size_t size, cv::Mat& dst, JpegErrors& errors) {
  jpeg_decompress_struct info;
  info.err = useJpegErrors(errors);
  if (setjmp(errors.jump)) {
    jpeg_destroy_decompress(&info);
    return false;
  }
  jpeg_create_decompress(&info);
  jpeg_mem_src(&info, bytes, static_cast<unsigned long>(size));
  jpeg_read_header(&info, TRUE);
  const bool grey = info.num_components == 1;
#ifdef JCS_EXTENSIONS
  info.out_color_space = grey ? JCS_GRAYSCALE : JCS_EXT_BGR;  // libjpeg-turbo writes BGR itself
#else
  info.out_color_space = grey ? JCS_GRAYSCALE : JCS_RGB;
#endif
  jpeg_start_decompress(&info);
  dst.create(static_cast<int>(info.output_height), static_cast<int>(info.output_width), grey ? CV_8UC1 : CV_8UC3);
  while (info.output_scanline < info.output_height) {
    JSAMPROW row = dst.ptr<JSAMPLE>(static_cast<int>(info.output_scanline));
    jpeg_read_scanlines(&info, &row, 1);
  }
#ifndef JCS_EXTENSIONS
  if (!grey) {
    for (int r = 0; r < dst.rows; ++r) {
      uint8_t* p = dst.ptr<uint8_t>(r);
      for (int c = 0; c < dst.cols; ++c, p += 3) std::swap(p[0], p[2]);
    }
  }
#endif
  jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
  return true;
}

}  // namespace

bool jpegAvailable() { return true; }

bool decodeJpeg(const uint8_t* bytes, std::size_t size, cv::Mat& dst, std::string* error) {
  if (!looksLikeJpeg(bytes, size)) {
    if (error) *error = "not a JPEG (no start-of-image marker)";
    return false;
  }
  JpegErrors errors;
  errors.message[0] = '\0';
  if (!decodeRows(bytes, size, dst, errors)) {
    if (error) *error = std::string("corrupt or truncated JPEG (") + errors.message + ")";
    return false;
  }
  return true;
}

#else

bool jpegAvailable() { return false; }

bool decodeJpeg(const uint8_t*, std::size_t, cv::Mat&, std::string* error) {
  if (error) *error = "JPEG: plumb was built without libjpeg (apt install libjpeg62-turbo-dev)";
  return false;
}

#endif

}  // namespace plumb

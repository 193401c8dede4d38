#include "drivers/image/jpeg_decoder.h"

#include <cstdio>
#include <utility>

#if PLUMB_HAVE_LIBJPEG
#include <csetjmp>
// jpeglib.h needs FILE and size_t declared first.
#include <jpeglib.h>
#endif

namespace plumb {

bool looksLikeJpeg(const uint8_t* bytes, std::size_t size) {
  return size >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF;
}

#if PLUMB_HAVE_LIBJPEG

namespace {

// libjpeg's error_exit must not return: keep the message and jump back into decodeRows().
struct ErrorManager {
  jpeg_error_mgr base;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
  char warning[JMSG_LENGTH_MAX];  // the first warning (a truncated or corrupt stream)
};

void onError(j_common_ptr info) {
  auto* errors = reinterpret_cast<ErrorManager*>(info->err);
  (*info->err->format_message)(info, errors->message);
  std::longjmp(errors->jump, 1);
}
void onMessage(j_common_ptr) {}  // nothing is printed: problems become the decoder's error
// libjpeg only WARNS about a truncated stream ("Premature end of JPEG file") or corrupt data, and
// fills the missing rows with grey: a silently wrong image (a truncated PNG is refused). Every
// warning is kept and fails the decode, like an error.
void onEmit(j_common_ptr info, int level) {
  if (level >= 0) return;  // trace messages
  auto* errors = reinterpret_cast<ErrorManager*>(info->err);
  if (errors->warning[0] == '\0') (*info->err->format_message)(info, errors->warning);
  ++info->err->num_warnings;
}

// The libjpeg calls, apart so that setjmp's frame holds no objects with destructors. The Mat is
// created inside, after the header is known.
bool decodeRows(const uint8_t* bytes, std::size_t size, cv::Mat& dst, ErrorManager& errors) {
  jpeg_decompress_struct info;
  info.err = jpeg_std_error(&errors.base);
  errors.base.error_exit = onError;
  errors.base.output_message = onMessage;
  errors.base.emit_message = onEmit;
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
  const bool clean = errors.base.num_warnings == 0;
  jpeg_destroy_decompress(&info);
  if (!clean) std::snprintf(errors.message, sizeof errors.message, "%s", errors.warning);
  return clean;
}

}  // namespace

bool jpegAvailable() { return true; }

bool decodeJpeg(const uint8_t* bytes, std::size_t size, cv::Mat& dst, std::string* error) {
  if (!looksLikeJpeg(bytes, size)) {
    if (error) *error = "not a JPEG (no start-of-image marker)";
    return false;
  }
  ErrorManager errors;
  errors.message[0] = '\0';
  errors.warning[0] = '\0';
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

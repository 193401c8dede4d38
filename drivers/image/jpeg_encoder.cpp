#include "drivers/image/jpeg_encoder.h"

#include <cstdio>
#include <cstdlib>

#if PLUMB_HAVE_LIBJPEG
#include <csetjmp>
// jpeglib.h needs FILE and size_t declared first.
#include <jpeglib.h>
#endif

namespace plumb {

#if PLUMB_HAVE_LIBJPEG

namespace {

// libjpeg's error_exit must not return: keep the message and jump back into compressRows().
struct EncoderErrors {
  jpeg_error_mgr base;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void onEncoderError(j_common_ptr info) {
  auto* errors = reinterpret_cast<EncoderErrors*>(info->err);
  (*info->err->format_message)(info, errors->message);
  std::longjmp(errors->jump, 1);
}
void onEncoderMessage(j_common_ptr) {}  // nothing is printed

// The libjpeg calls, apart so that setjmp's frame holds no objects with destructors. `pixels` are
// BGR with libjpeg-turbo's extensions, else RGB. libjpeg mallocs the output buffer
// (jpeg_mem_dest); the caller copies and frees it.
bool compressRows(const uint8_t* pixels, int width, int height, std::size_t stride, int quality, EncoderErrors& errors,
                  unsigned char** buffer, unsigned long* size) {
  jpeg_compress_struct info;
  info.err = jpeg_std_error(&errors.base);
  errors.base.error_exit = onEncoderError;
  errors.base.output_message = onEncoderMessage;
  if (setjmp(errors.jump)) {
    jpeg_destroy_compress(&info);
    return false;
  }
  jpeg_create_compress(&info);
  jpeg_mem_dest(&info, buffer, size);
  info.image_width = JDIMENSION(width);
  info.image_height = JDIMENSION(height);
  info.input_components = 3;
#ifdef JCS_EXTENSIONS
  info.in_color_space = JCS_EXT_BGR;  // libjpeg-turbo reads BGR itself
#else
  info.in_color_space = JCS_RGB;
#endif
  jpeg_set_defaults(&info);
  jpeg_set_quality(&info, quality, TRUE);
  jpeg_start_compress(&info, TRUE);
  while (info.next_scanline < info.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(pixels + std::size_t(info.next_scanline) * stride);
    jpeg_write_scanlines(&info, &row, 1);
  }
  jpeg_finish_compress(&info);
  jpeg_destroy_compress(&info);
  return true;
}

}  // namespace

bool encodeJpeg(const uint8_t* bgr, int width, int height, std::size_t stride, int quality,
                std::vector<uint8_t>* out, std::string* error) {
  if (width <= 0 || height <= 0 || quality < 1 || quality > 100) {
    if (error) *error = "JPEG encoder: bad image size or quality";
    return false;
  }
  const uint8_t* pixels = bgr;
#ifndef JCS_EXTENSIONS
  // Plain libjpeg reads RGB: swap into a copy.
  std::vector<uint8_t> rgb(std::size_t(height) * stride);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const uint8_t* src = bgr + std::size_t(y) * stride + std::size_t(x) * 3;
      uint8_t* dst = rgb.data() + std::size_t(y) * stride + std::size_t(x) * 3;
      dst[0] = src[2];
      dst[1] = src[1];
      dst[2] = src[0];
    }
  }
  pixels = rgb.data();
#endif
  EncoderErrors errors;
  errors.message[0] = '\0';
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  const bool ok = compressRows(pixels, width, height, stride, quality, errors, &buffer, &size);
  if (ok) out->assign(buffer, buffer + size);
  std::free(buffer);
  if (!ok && error) *error = std::string("JPEG encoder: ") + errors.message;
  return ok;
}

#else

bool encodeJpeg(const uint8_t*, int, int, std::size_t, int, std::vector<uint8_t>*, std::string* error) {
  if (error) *error = "this plumb was built without libjpeg (Debian: libjpeg62-turbo-dev)";
  return false;
}

#endif

}  // namespace plumb

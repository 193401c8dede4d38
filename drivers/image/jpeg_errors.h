#pragma once
// libjpeg's error handling for the JPEG decoder and encoder (drivers/image/jpeg_*.cpp): its
// error_exit must not return, so the handler keeps the message and longjmps back to the setjmp in
// the caller's libjpeg-only function (whose frame holds no objects with destructors). Include only
// where PLUMB_HAVE_LIBJPEG is set.
#include <csetjmp>
#include <cstdio>
// jpeglib.h needs FILE and size_t declared first.
#include <jpeglib.h>

namespace plumb {

struct JpegErrors {
  jpeg_error_mgr base;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

inline void jpegErrorExit(j_common_ptr info) {
  auto* errors = reinterpret_cast<JpegErrors*>(info->err);
  (*info->err->format_message)(info, errors->message);
  std::longjmp(errors->jump, 1);
}

// Points `info`'s error manager at `errors`, with jpegErrorExit and without warning output.
inline jpeg_error_mgr* useJpegErrors(JpegErrors& errors) {
  jpeg_error_mgr* manager = jpeg_std_error(&errors.base);
  errors.base.error_exit = jpegErrorExit;
  errors.base.output_message = [](j_common_ptr) {};  // warnings (corrupt-data remarks) are not printed
  return manager;
}

}  // namespace plumb

#include "drivers/image/png_encoder.h"

#include "drivers/common/atomic_file.h"

#include <png.h>

#include <csetjmp>
#include <cstdio>

namespace plumb {
namespace {

// zlib.h's strategy values (png_set_compression_strategy takes them; png.h does not name them).
constexpr int kZlibDefaultStrategy = 0;
constexpr int kZlibRle = 3;

constexpr bool kLittleEndianHost = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;

struct WriteContext {
  std::vector<uint8_t>* out = nullptr;
  char error[160] = {};
};

void onError(png_structp png, png_const_charp message) {
  auto* context = static_cast<WriteContext*>(png_get_error_ptr(png));
  std::snprintf(context->error, sizeof(context->error), "%s", message);
  png_longjmp(png, 1);
}
void onWarning(png_structp, png_const_charp) {}
void appendBytes(png_structp png, png_bytep data, std::size_t length) {
  auto* context = static_cast<WriteContext*>(png_get_io_ptr(png));
  context->out->insert(context->out->end(), data, data + length);
}
void flush(png_structp) {}

int colourTypeOf(int channels) {
  switch (channels) {
    case 1: return PNG_COLOR_TYPE_GRAY;
    case 3: return PNG_COLOR_TYPE_RGB;
    case 4: return PNG_COLOR_TYPE_RGB_ALPHA;
    default: return -1;
  }
}

// The libpng calls, apart so that setjmp's frame holds no objects with destructors.
bool encodeRows(const cv::Mat& image, const PngEncodeOptions& options, WriteContext& context) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &context, onError, onWarning);
  if (png == nullptr) {
    std::snprintf(context.error, sizeof(context.error), "out of memory");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (info == nullptr || setjmp(png_jmpbuf(png))) {
    if (info == nullptr) std::snprintf(context.error, sizeof(context.error), "out of memory");
    png_destroy_write_struct(&png, info != nullptr ? &info : nullptr);
    return false;
  }
  png_set_write_fn(png, &context, appendBytes, flush);
  if (options.sub_filter_only) png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_compression_level(png, options.compression_level);
  png_set_compression_strategy(png, options.rle_strategy ? kZlibRle : kZlibDefaultStrategy);
  const int bit_depth = image.depth() == CV_16U ? 16 : 8;
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.cols), static_cast<png_uint_32>(image.rows),
               bit_depth, colourTypeOf(image.channels()), PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_set_bgr(png);                                        // rows are BGR(A); PNG stores RGB(A)
  if (bit_depth == 16 && kLittleEndianHost) png_set_swap(png);  // PNG samples are big-endian
  for (int r = 0; r < image.rows; ++r) png_write_row(png, image.ptr<png_byte>(r));
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

Status encodePng(const cv::Mat& image, const PngEncodeOptions& options, std::vector<uint8_t>& out) {
  if (image.empty() || (image.depth() != CV_8U && image.depth() != CV_16U) || colourTypeOf(image.channels()) < 0)
    return Status::Error("PNG encoder: needs an 8- or 16-bit image with 1, 3 or 4 channels");
  if (options.compression_level < 0 || options.compression_level > 9)
    return Status::Error("PNG encoder: compression level must be 0..9");
  const std::size_t start = out.size();
  WriteContext context;
  context.out = &out;
  if (!encodeRows(image, options, context)) {
    out.resize(start);
    return Status::Error(std::string("PNG encoder: ") + context.error);
  }
  return Status::Ok();
}

Status writePngOutput(const std::string& path, const cv::Mat& image, const PngEncodeOptions& options) {
  std::vector<uint8_t> bytes;
  const Status encoded = encodePng(image, options, bytes);
  if (!encoded.ok()) return Status::Error(path + ": " + encoded.message());
  return writeFileAtomically(path, bytes.data(), bytes.size());
}

Status writePngFile(const std::string& path, const cv::Mat& image, const PngEncodeOptions& options) {
  std::vector<uint8_t> bytes;
  const Status encoded = encodePng(image, options, bytes);
  if (!encoded.ok()) return Status::Error(path + ": " + encoded.message());
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) return Status::Error(path + ": cannot write (missing folder or no permission?)");
  const bool written = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
  if (std::fclose(file) != 0 || !written) return Status::Error(path + ": write failed");
  return Status::Ok();
}

}  // namespace plumb

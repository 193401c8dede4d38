#include "drivers/dataset/png_decoder.h"

#include <png.h>

#include "drivers/dataset/png_fast_path.h"

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace plumb {

namespace {

// Enough for libpng's read structures, zlib's inflate state and 32 KiB window, and the row
// buffers of images up to a few thousand pixels wide; reset for every image.
constexpr std::size_t kArenaBytes = 512 * 1024;
constexpr std::size_t kArenaAlignment = 16;

// libpng sizes an ancillary chunk's buffer from the length field in the file and allocates it
// before reading: a 140-byte file whose tEXt claims 1.8 GB asked malloc for 1.8 GB (found by the
// png_decoder fuzz target). No chunk can be longer than the file, so chunk buffers (and the
// inflated text or ICC profile of one) are bounded by the file size, with a floor for small files
// whose compressed profile expands; and no libpng request may exceed kMaxLibpngRequest at all (its
// row buffers for the largest accepted image, 8192 px x 4 channels x 16 bits, need 64 KiB each).
constexpr std::size_t kMinChunkLimit = 1u << 20;
constexpr std::size_t kMaxLibpngRequest = 64u << 20;

constexpr bool kLittleEndianHost = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;

}  // namespace

// The callbacks reach the decoder through the pointers libpng hands back (error, mem, io).
struct PngCallbacks {
  static PngDecoder& decoderOf(png_structp png, void* pointer) {
    (void)png;
    return *static_cast<PngDecoder*>(pointer);
  }

  // libpng's error handler must not return: record the message and jump back to the setjmp in
  // readHeader()/decodePixels().
  static void onError(png_structp png, png_const_charp message) {
    PngDecoder& d = decoderOf(png, png_get_error_ptr(png));
    std::snprintf(d.error_, sizeof(d.error_), "corrupt or truncated PNG (%s)", message);
    png_longjmp(png, 1);
  }
  // Warnings (unknown chunks, sRGB profile remarks) do not affect the pixels: not printed.
  static void onWarning(png_structp, png_const_charp) {}

  static png_voidp allocate(png_structp png, png_alloc_size_t size) {
    PngDecoder& d = decoderOf(png, png_get_mem_ptr(png));
    const std::size_t start = (d.arena_used_ + kArenaAlignment - 1) & ~(kArenaAlignment - 1);
    if (start + size <= d.arena_.size()) {
      d.arena_used_ = start + size;
      return d.arena_.data() + start;
    }
    if (size > kMaxLibpngRequest) return nullptr;  // libpng reports "out of memory": an error, no abort
    ++d.arena_overflows_;
    return std::malloc(size);
  }
  static void release(png_structp png, png_voidp pointer) {
    PngDecoder& d = decoderOf(png, png_get_mem_ptr(png));
    const auto* p = static_cast<const unsigned char*>(pointer);
    if (p >= d.arena_.data() && p < d.arena_.data() + d.arena_.size()) return;  // freed with the arena
    std::free(pointer);
  }

  static void readBytes(png_structp png, png_bytep out, std::size_t length) {
    PngDecoder& d = decoderOf(png, png_get_io_ptr(png));
    if (length > d.size_ - d.offset_) png_error(png, "file ends early");
    std::memcpy(out, d.bytes_ + d.offset_, length);
    d.offset_ += length;
  }
};

std::size_t pngFileBound(int width, int height, int bytes_per_pixel) {
  const std::size_t filtered = std::size_t(height) * (std::size_t(width) * std::size_t(bytes_per_pixel) + 1);
  return filtered + filtered / 1000 + (std::size_t(64) << 10);
}

void PngDecoder::reserve(int width, int height) {
#ifdef PLUMB_HAVE_LIBDEFLATE
  if (fast_ && width > 0 && height > 0) {
    fast_->reserve(pngFileBound(width, height, 3), std::size_t(height) * (std::size_t(width) * 3 + 1),
                   std::size_t(width) * 3);
  }
#else
  (void)width;
  (void)height;
#endif
}

PngDecoder::PngDecoder() : arena_(kArenaBytes) {
  rows_.reserve(1024);
#ifdef PLUMB_HAVE_LIBDEFLATE
  fast_ = std::make_unique<PngFastPath>();
#endif
}

PngDecoder::~PngDecoder() { destroy(); }

void PngDecoder::destroy() {
  if (png_ == nullptr) return;
  auto png = static_cast<png_structp>(png_);
  auto info = static_cast<png_infop>(info_);
  png_destroy_read_struct(&png, info != nullptr ? &info : nullptr, nullptr);
  png_ = nullptr;
  info_ = nullptr;
}

bool PngDecoder::readHeader(const uint8_t* bytes, std::size_t size, PngHeader* header) {
  destroy();
  arena_used_ = 0;
  bytes_ = bytes;
  size_ = size;
  offset_ = 0;
  error_[0] = '\0';
  if (size < 8 || png_sig_cmp(bytes, 0, 8) != 0) {
    std::snprintf(error_, sizeof(error_), "corrupt or not a PNG file (no PNG signature)");
    return false;
  }
  png_structp png = png_create_read_struct_2(PNG_LIBPNG_VER_STRING, this, &PngCallbacks::onError,
                                             &PngCallbacks::onWarning, this, &PngCallbacks::allocate,
                                             &PngCallbacks::release);
  if (png == nullptr) {
    std::snprintf(error_, sizeof(error_), "libpng could not start (version mismatch or no memory)");
    return false;
  }
  png_ = png;
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    std::snprintf(error_, sizeof(error_), "libpng could not start (no memory)");
    destroy();
    return false;
  }
  info_ = info;
  // Only plain locals from here to the end of the libpng calls: a longjmp skips destructors.
  if (setjmp(png_jmpbuf(png))) {
    destroy();
    return false;
  }
  png_set_read_fn(png, this, &PngCallbacks::readBytes);
  png_set_chunk_malloc_max(png, std::max(size, kMinChunkLimit));
  png_read_info(png, info);
  png_uint_32 width = 0, height = 0;
  int bit_depth = 0, colour_type = 0, interlace = 0;
  png_get_IHDR(png, info, &width, &height, &bit_depth, &colour_type, &interlace, nullptr, nullptr);
  stored_bit_depth_ = bit_depth;
  colour_type_ = colour_type;
  interlace_ = interlace;
  if (colour_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (colour_type == PNG_COLOR_TYPE_GRAY && bit_depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (bit_depth == 16 && kLittleEndianHost) png_set_swap(png);  // PNG stores 16-bit big-endian
  if ((colour_type & PNG_COLOR_MASK_COLOR) != 0) png_set_bgr(png);  // OpenCV's channel order
  if (interlace != PNG_INTERLACE_NONE) (void)png_set_interlace_handling(png);
  png_read_update_info(png, info);
  header_.width = static_cast<int>(width);
  header_.height = static_cast<int>(height);
  header_.bit_depth = png_get_bit_depth(png, info);
  header_.channels = png_get_channels(png, info);
  *header = header_;
  return true;
}

bool PngDecoder::decodePixels(cv::Mat& dst) {
  if (png_ == nullptr) {
    std::snprintf(error_, sizeof(error_), "no PNG header read");
    return false;
  }
  auto png = static_cast<png_structp>(png_);
  auto info = static_cast<png_infop>(info_);
  dst.create(header_.height, header_.width, CV_MAKETYPE(header_.bit_depth == 16 ? CV_16U : CV_8U, header_.channels));
#ifdef PLUMB_HAVE_LIBDEFLATE
  if (fast_ && PngFastPath::handles(stored_bit_depth_, colour_type_, interlace_)) {
    destroy();  // libpng has read the header; the fast path reads the whole file itself
    return fast_->decode(bytes_, size_, stored_bit_depth_, colour_type_, dst, error_, sizeof(error_));
  }
#endif
  if (png_get_rowbytes(png, info) != dst.cols * dst.elemSize()) {
    std::snprintf(error_, sizeof(error_), "unexpected PNG row size");
    destroy();
    return false;
  }
  if (rows_.size() < static_cast<std::size_t>(header_.height)) rows_.resize(static_cast<std::size_t>(header_.height));
  for (int r = 0; r < header_.height; ++r) rows_[static_cast<std::size_t>(r)] = dst.ptr<unsigned char>(r);
  if (setjmp(png_jmpbuf(png))) {
    destroy();
    return false;
  }
  png_read_image(png, rows_.data());
  png_read_end(png, nullptr);  // checks the chunks after the pixels (CRCs, IEND)
  destroy();
  return true;
}

}  // namespace plumb

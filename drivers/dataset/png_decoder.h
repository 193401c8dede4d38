#pragma once
// PngDecoder: PNG bytes -> a caller's cv::Mat, with libpng directly and no heap allocation once the
// Mat has its size (every frame of a replay after the first).
//
// Why not cv::imdecode: it allocates ~5 times per image (Mat headers, a decoder object, buffers)
// and converts through an intermediate Mat; a replayed sequence should cost what a camera costs.
// libpng itself allocates its read structures per image (it cannot be reset between images): they
// come from a fixed arena owned by the decoder (reset per image), so a decode makes no malloc
// either; requests beyond the arena (odd PNGs with huge text or ICC chunks) fall back to malloc.
//
// Speed: the layouts recordings use (non-interlaced 8/16-bit grey or colour, with or without alpha)
// are decoded by PngFastPath (libdeflate, one inflate call, about half the time of libpng + zlib)
// when plumb is built with libdeflate; libpng reads the header in every case and decodes the rest.
//
// Accepted: non-interlaced or interlaced PNGs of any colour type; the result keeps the stored bit
// depth and channel count the way the TUM loader checks them (grey 1, grey+alpha 2, colour 3 as
// BGR, colour+alpha 4 as BGRA, palette expanded to BGR; 1/2/4-bit grey widened to 8 bits). CRCs
// and the zlib checksum are verified, so corruption is an error, not noise in the pixels.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <memory>

#include <opencv2/core.hpp>

namespace plumb {

class PngFastPath;

struct PngHeader {
  int width = 0;
  int height = 0;
  int bit_depth = 0;  // after the transforms: 8 or 16
  int channels = 0;   // after the transforms: 1..4
};

// An upper bound on the file size of a PNG of width x height with bytes_per_pixel (3: BGR 8-bit,
// 2: 16-bit depth): the filtered scanlines, deflate's worst case for incompressible data (stored
// blocks, ~0.01 % overhead), chunk headers and ancillary chunks (64 KiB). Readers size their
// buffers with it once, so decoding a stream of such images allocates nothing.
std::size_t pngFileBound(int width, int height, int bytes_per_pixel);

class PngDecoder {
 public:
  PngDecoder();
  ~PngDecoder();
  PngDecoder(const PngDecoder&) = delete;
  PngDecoder& operator=(const PngDecoder&) = delete;

  // Reads the header of `bytes` (no pixels). False with error() set when it is not a readable PNG.
  bool readHeader(const uint8_t* bytes, std::size_t size, PngHeader* header);
  // Decodes the image whose header readHeader() just read into dst, which is (re)allocated only
  // when its size or type differ. Call right after a successful readHeader() on the same bytes.
  bool decodePixels(cv::Mat& dst);
  // Sizes the scratch for images up to width x height with up to 3 bytes a pixel (BGR 8-bit, or
  // 16-bit depth), so that decoding them allocates nothing (larger files still decode: the
  // scratch then grows, with headroom).
  void reserve(int width, int height);
  // What went wrong, e.g. "corrupt or truncated PNG (IDAT: CRC error)". Valid until the next call.
  const char* error() const { return error_; }
  // malloc calls libpng made beyond the arena since construction (0 for ordinary PNGs).
  uint64_t arenaOverflows() const { return arena_overflows_; }

 private:
  friend struct PngCallbacks;  // libpng's error, memory and read callbacks (png_decoder.cpp)
  void destroy();

  std::unique_ptr<PngFastPath> fast_;  // libdeflate decoding of the common layouts; null without it
  int stored_bit_depth_ = 0, colour_type_ = 0, interlace_ = 0;  // IHDR as stored
  void* png_ = nullptr;   // png_structp of the image being read
  void* info_ = nullptr;  // png_infop
  const uint8_t* bytes_ = nullptr;
  std::size_t size_ = 0;
  std::size_t offset_ = 0;
  PngHeader header_;
  std::vector<unsigned char> arena_;
  std::size_t arena_used_ = 0;
  uint64_t arena_overflows_ = 0;
  std::vector<unsigned char*> rows_;  // row pointers into dst, grown only for taller images
  char error_[160] = {};
};

}  // namespace plumb

#pragma once
// The common PNG layouts of RGB-D recordings (non-interlaced, 8 or 16 bits per sample, grey / grey+
// alpha / colour / colour+alpha) decoded with libdeflate instead of libpng + zlib: libdeflate
// inflates a whole zlib stream in one call about twice as fast, which is most of a PNG's cost.
// Chunk CRCs and the zlib checksum are verified as libpng would. PngDecoder uses it when built
// with libdeflate (PLUMB_HAVE_LIBDEFLATE) and falls back to libpng for every other layout.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>

namespace plumb {

class PngFastPath {
 public:
  PngFastPath();
  ~PngFastPath();
  PngFastPath(const PngFastPath&) = delete;
  PngFastPath& operator=(const PngFastPath&) = delete;

  // Scratch for files up to file_bytes whose scanlines (filter bytes included) need up to
  // filtered_bytes, rows up to row_bytes: allocated now instead of at the first such file.
  void reserve(std::size_t file_bytes, std::size_t filtered_bytes, std::size_t row_bytes);
  // Whether this layout is handled here (IHDR values as stored).
  static bool handles(int bit_depth, int colour_type, int interlace);
  // Decodes the whole file into dst (already created with the right size and type: BGR order,
  // native-endian 16-bit samples). False with a message in `error` (size error_size).
  bool decode(const uint8_t* bytes, std::size_t size, int bit_depth, int colour_type, cv::Mat& dst, char* error,
              std::size_t error_size);

 private:
  // Scratch that every decode writes before reading, grown with 50 % headroom and NOT zero-filled
  // (new uint8_t[n]): the headroom costs address space, not resident memory.
  struct Scratch {
    std::unique_ptr<uint8_t[]> bytes;
    std::size_t size = 0;
    uint8_t* data() { return bytes.get(); }
    void ensure(std::size_t needed);
  };
  void* decompressor_ = nullptr;        // struct libdeflate_decompressor*
  Scratch compressed_;                  // the IDAT payloads, concatenated (one zlib stream)
  Scratch filtered_;                    // inflated scanlines (filter byte + row), unfiltered in place
  std::vector<uint8_t> zero_row_;       // the row "above" the first one
};

}  // namespace plumb

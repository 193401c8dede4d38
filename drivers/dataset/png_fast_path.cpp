#include "drivers/dataset/png_fast_path.h"

#ifdef PLUMB_HAVE_LIBDEFLATE
#include <libdeflate.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace plumb {

// Grows with 50 % headroom: compressed sizes vary from frame to frame, and a buffer sized to the
// largest so far would reallocate whenever a later frame beats it. Contents are not kept.
void PngFastPath::Scratch::ensure(std::size_t needed) {
  if (size >= needed) return;
  size = needed + needed / 2;
  bytes.reset(new uint8_t[size]);  // default-initialised: untouched pages stay out of RSS
}

void PngFastPath::reserve(std::size_t file_bytes, std::size_t filtered_bytes, std::size_t row_bytes) {
  compressed_.ensure(file_bytes);
  filtered_.ensure(filtered_bytes);
  if (zero_row_.size() < row_bytes) zero_row_.assign(row_bytes, 0);
}

namespace {

uint32_t bigEndian32(const uint8_t* p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}

int channelsOf(int colour_type) {
  switch (colour_type) {
    case 0: return 1;  // grey
    case 2: return 3;  // colour
    case 4: return 2;  // grey + alpha
    case 6: return 4;  // colour + alpha
    default: return 0;
  }
}

// The predictor of filter type 4 (PNG specification, "Paeth"): whichever of left, above and
// upper-left is closest to left + above - upper-left, ties in that order.
inline uint8_t paeth(int left, int above, int upper_left) {
  const int pa = std::abs(above - upper_left);
  const int pb = std::abs(left - upper_left);
  const int pc = std::abs(left + above - 2 * upper_left);
  if (pa <= pb && pa <= pc) return uint8_t(left);
  return uint8_t(pb <= pc ? above : upper_left);
}

// Undoes one scanline's filter in place; `above` is the previous scanline, already unfiltered.
bool unfilter(uint8_t type, uint8_t* row, const uint8_t* above, std::size_t n, std::size_t bpp) {
  switch (type) {
    case 0:
      return true;
    case 1:
      for (std::size_t i = bpp; i < n; ++i) row[i] = uint8_t(row[i] + row[i - bpp]);
      return true;
    case 2:
      for (std::size_t i = 0; i < n; ++i) row[i] = uint8_t(row[i] + above[i]);
      return true;
    case 3:
      for (std::size_t i = 0; i < bpp; ++i) row[i] = uint8_t(row[i] + (above[i] >> 1));
      for (std::size_t i = bpp; i < n; ++i) row[i] = uint8_t(row[i] + ((row[i - bpp] + above[i]) >> 1));
      return true;
    case 4:
      for (std::size_t i = 0; i < bpp; ++i) row[i] = uint8_t(row[i] + above[i]);  // left = upper-left = 0
      for (std::size_t i = bpp; i < n; ++i) row[i] = uint8_t(row[i] + paeth(row[i - bpp], above[i], above[i - bpp]));
      return true;
    default:
      return false;
  }
}

// One unfiltered scanline into a Mat row: colour channels to OpenCV's B, G, R order, 16-bit
// samples from PNG's big-endian to the host's order.
void convertRow(const uint8_t* in, uint8_t* out, int width, int channels, int bit_depth) {
  const bool colour = channels >= 3;
  if (bit_depth == 8) {
    if (!colour) {
      std::memcpy(out, in, std::size_t(width) * std::size_t(channels));
      return;
    }
    for (int x = 0; x < width; ++x, in += channels, out += channels) {
      out[0] = in[2];
      out[1] = in[1];
      out[2] = in[0];
      if (channels == 4) out[3] = in[3];
    }
    return;
  }
  auto* out16 = reinterpret_cast<uint16_t*>(out);
  for (int x = 0; x < width; ++x, in += 2 * channels, out16 += channels) {
    for (int c = 0; c < channels; ++c) {
      const int from = colour && c < 3 ? 2 - c : c;
      out16[c] = uint16_t(in[2 * from] << 8 | in[2 * from + 1]);
    }
  }
}

}  // namespace

PngFastPath::PngFastPath() : decompressor_(libdeflate_alloc_decompressor()) {}

PngFastPath::~PngFastPath() {
  libdeflate_free_decompressor(static_cast<libdeflate_decompressor*>(decompressor_));
}

bool PngFastPath::handles(int bit_depth, int colour_type, int interlace) {
  return interlace == 0 && (bit_depth == 8 || bit_depth == 16) && channelsOf(colour_type) > 0;
}

bool PngFastPath::decode(const uint8_t* bytes, std::size_t size, int bit_depth, int colour_type, cv::Mat& dst,
                         char* error, std::size_t error_size) {
  if (decompressor_ == nullptr) {
    std::snprintf(error, error_size, "libdeflate could not start (no memory)");
    return false;
  }
  // 1. Chunks after the 8-byte signature: CRCs checked, IDAT payloads gathered, up to IEND.
  std::size_t compressed_size = 0;
  bool ended = false;
  compressed_.ensure(size);  // the IDAT payloads are part of the file
  for (std::size_t at = 8; !ended;) {
    if (size - at < 12) {
      std::snprintf(error, error_size, "corrupt or truncated PNG (file ends early)");
      return false;
    }
    const uint32_t length = bigEndian32(bytes + at);
    if (length > size - at - 12) {
      std::snprintf(error, error_size, "corrupt or truncated PNG (file ends early)");
      return false;
    }
    const uint8_t* type = bytes + at + 4;
    const uint8_t* data = type + 4;
    if (libdeflate_crc32(0, type, length + 4) != bigEndian32(data + length)) {
      std::snprintf(error, error_size, "corrupt or truncated PNG (%.4s: CRC error)", reinterpret_cast<const char*>(type));
      return false;
    }
    if (std::memcmp(type, "IDAT", 4) == 0) {
      std::memcpy(compressed_.data() + compressed_size, data, length);
      compressed_size += length;
    }
    ended = std::memcmp(type, "IEND", 4) == 0;
    at += 12 + std::size_t(length);
  }
  // 2. One inflate of the whole stream into exactly height scanlines (adler32 checked).
  const int channels = channelsOf(colour_type);
  const std::size_t bpp = std::size_t(channels) * std::size_t(bit_depth / 8);
  const std::size_t row_bytes = std::size_t(dst.cols) * bpp;
  const std::size_t expected = std::size_t(dst.rows) * (row_bytes + 1);
  filtered_.ensure(expected);
  if (zero_row_.size() < row_bytes) zero_row_.assign(row_bytes, 0);
  const libdeflate_result r = libdeflate_zlib_decompress(static_cast<libdeflate_decompressor*>(decompressor_),
                                                         compressed_.data(), compressed_size, filtered_.data(),
                                                         expected, nullptr);
  if (r != LIBDEFLATE_SUCCESS) {
    std::snprintf(error, error_size, "corrupt or truncated PNG (compressed pixels: %s)",
                  r == LIBDEFLATE_SHORT_OUTPUT ? "too few" : r == LIBDEFLATE_INSUFFICIENT_SPACE ? "too many" : "bad data");
    return false;
  }
  // 3. Unfilter each scanline in place (the one above is done already), then convert into dst.
  const uint8_t* above = zero_row_.data();
  for (int y = 0; y < dst.rows; ++y) {
    uint8_t* line = filtered_.data() + std::size_t(y) * (row_bytes + 1);
    if (!unfilter(line[0], line + 1, above, row_bytes, bpp)) {
      std::snprintf(error, error_size, "corrupt PNG (row %d: unknown filter type %d)", y, int(line[0]));
      return false;
    }
    convertRow(line + 1, dst.ptr<uint8_t>(y), dst.cols, channels, bit_depth);
    above = line + 1;
  }
  return true;
}

}  // namespace plumb

#endif  // PLUMB_HAVE_LIBDEFLATE

#ifndef PLUMB_HAVE_LIBDEFLATE
namespace plumb {
// Without libdeflate PngDecoder never creates a fast path, but its unique_ptr still needs these.
PngFastPath::PngFastPath() = default;
PngFastPath::~PngFastPath() = default;
}  // namespace plumb
#endif

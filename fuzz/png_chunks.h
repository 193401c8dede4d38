#pragma once
// A PNG file as a list of chunks, for the PNG fuzzer's structure-aware mutator
// (png_decoder_fuzzer.cpp): parse, edit chunks or pixels, and write back with correct CRCs and a
// valid zlib stream, so mutated inputs reach the decoder's pixel code instead of stopping at a
// checksum. Header-only, fuzzer-only.
#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace plumb::fuzz {

struct PngChunk {
  std::string type;  // 4 characters
  std::vector<uint8_t> data;
};

struct PngFile {
  std::vector<PngChunk> chunks;
};

constexpr uint8_t kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

inline uint32_t readBigEndian32(const uint8_t* p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}

inline void appendBigEndian32(uint32_t v, std::vector<uint8_t>* out) {
  for (int shift = 24; shift >= 0; shift -= 8) out->push_back(uint8_t(v >> shift));
}

// Signature, then chunks up to the end of the bytes (CRCs not checked: the mutator rewrites them).
inline bool parsePng(const uint8_t* bytes, std::size_t size, PngFile* png) {
  png->chunks.clear();
  if (size < 8 || std::memcmp(bytes, kPngSignature, 8) != 0) return false;
  std::size_t at = 8;
  while (size - at >= 12) {
    const uint32_t length = readBigEndian32(bytes + at);
    if (length > size - at - 12) return false;
    PngChunk chunk;
    chunk.type.assign(reinterpret_cast<const char*>(bytes + at + 4), 4);
    chunk.data.assign(bytes + at + 8, bytes + at + 8 + length);
    png->chunks.push_back(std::move(chunk));
    at += 12 + std::size_t(length);
  }
  return !png->chunks.empty();
}

inline std::vector<uint8_t> writePng(const PngFile& png) {
  std::vector<uint8_t> out(kPngSignature, kPngSignature + 8);
  for (const PngChunk& chunk : png.chunks) {
    appendBigEndian32(uint32_t(chunk.data.size()), &out);
    const std::size_t type_at = out.size();
    out.insert(out.end(), chunk.type.begin(), chunk.type.end());
    out.insert(out.end(), chunk.data.begin(), chunk.data.end());
    const uLong crc = crc32(0, out.data() + type_at, uInt(4 + chunk.data.size()));
    appendBigEndian32(uint32_t(crc), &out);
  }
  return out;
}

struct PngLayout {
  uint32_t width = 0, height = 0;
  int bit_depth = 0, colour_type = 0, interlace = 0;
};

inline bool readLayout(const PngFile& png, PngLayout* layout) {
  if (png.chunks.empty() || png.chunks[0].type != "IHDR" || png.chunks[0].data.size() != 13) return false;
  const uint8_t* d = png.chunks[0].data.data();
  layout->width = readBigEndian32(d);
  layout->height = readBigEndian32(d + 4);
  layout->bit_depth = d[8];
  layout->colour_type = d[9];
  layout->interlace = d[12];
  return true;
}

inline std::vector<uint8_t> ihdrData(const PngLayout& layout) {
  std::vector<uint8_t> d;
  appendBigEndian32(layout.width, &d);
  appendBigEndian32(layout.height, &d);
  d.push_back(uint8_t(layout.bit_depth));
  d.push_back(uint8_t(layout.colour_type));
  d.push_back(0);  // compression: deflate
  d.push_back(0);  // filter method: adaptive
  d.push_back(uint8_t(layout.interlace));
  return d;
}

inline int samplesPerPixel(int colour_type) {
  switch (colour_type) {
    case 0: return 1;
    case 2: return 3;
    case 3: return 1;
    case 4: return 2;
    case 6: return 4;
    default: return 0;
  }
}

// The (width, height) of each sub-image the IHDR implies: one, or Adam7's seven passes.
template <typename PassFn>
void forEachPass(const PngLayout& l, PassFn pass) {
  if (l.interlace == 0) {
    pass(std::size_t(l.width), std::size_t(l.height));
    return;
  }
  static const int kStart[7][2] = {{0, 0}, {4, 0}, {0, 4}, {2, 0}, {0, 2}, {1, 0}, {0, 1}};
  static const int kStep[7][2] = {{8, 8}, {8, 8}, {4, 8}, {4, 4}, {2, 4}, {2, 2}, {1, 2}};
  for (int p = 0; p < 7; ++p) {
    const std::size_t w = l.width > uint32_t(kStart[p][0]) ? (l.width - kStart[p][0] + kStep[p][0] - 1) / kStep[p][0] : 0;
    const std::size_t h = l.height > uint32_t(kStart[p][1]) ? (l.height - kStart[p][1] + kStep[p][1] - 1) / kStep[p][1] : 0;
    pass(w, h);
  }
}

inline std::size_t bitsPerPixel(const PngLayout& l) {
  return std::size_t(samplesPerPixel(l.colour_type)) * std::size_t(l.bit_depth);
}

// Bytes of the filtered scanlines (filter byte + packed row) the IHDR implies; 0 if invalid.
inline std::size_t filteredSize(const PngLayout& l) {
  const std::size_t bits = bitsPerPixel(l);
  if (bits == 0) return 0;
  std::size_t total = 0;
  forEachPass(l, [&](std::size_t w, std::size_t h) {
    if (w > 0 && h > 0) total += h * (1 + (w * bits + 7) / 8);
  });
  return total;
}

// Calls row(offset) with the offset of every scanline's filter byte below `limit` (a header may
// claim billions of rows; only those inside the buffer matter).
template <typename RowFn>
void forEachRow(const PngLayout& l, std::size_t limit, RowFn row) {
  const std::size_t bits = bitsPerPixel(l);
  if (bits == 0) return;
  std::size_t at = 0;
  forEachPass(l, [&](std::size_t w, std::size_t h) {
    if (w == 0 || h == 0) return;
    for (std::size_t y = 0; y < h && at < limit; ++y, at += 1 + (w * bits + 7) / 8) row(at);
  });
}

// All IDAT payloads, concatenated and inflated (at most `limit` bytes); false if not a zlib stream.
inline bool inflateIdat(const PngFile& png, std::size_t limit, std::vector<uint8_t>* out) {
  std::vector<uint8_t> compressed;
  for (const PngChunk& c : png.chunks)
    if (c.type == "IDAT") compressed.insert(compressed.end(), c.data.begin(), c.data.end());
  out->assign(limit, 0);
  z_stream z{};
  if (inflateInit(&z) != Z_OK) return false;
  z.next_in = compressed.data();
  z.avail_in = uInt(compressed.size());
  z.next_out = out->data();
  z.avail_out = uInt(out->size());
  const int r = inflate(&z, Z_FINISH);
  out->resize(z.total_out);
  inflateEnd(&z);
  return r == Z_STREAM_END || r == Z_BUF_ERROR || r == Z_OK;
}

// Replaces the IDAT chunks with `pixels` deflated at `level`, cut into `pieces` IDATs placed
// where the first IDAT was (before IEND if there was none).
inline void replaceIdat(PngFile* png, const std::vector<uint8_t>& filtered, int level, int pieces) {
  uLongf bound = compressBound(uLong(filtered.size()));
  std::vector<uint8_t> compressed(bound);
  if (compress2(compressed.data(), &bound, filtered.data(), uLong(filtered.size()), level) != Z_OK) return;
  compressed.resize(bound);
  std::vector<PngChunk> kept;
  std::size_t insert_at = SIZE_MAX;
  for (const PngChunk& c : png->chunks) {
    if (c.type != "IDAT") {
      kept.push_back(c);
    } else if (insert_at == SIZE_MAX) {
      insert_at = kept.size();
    }
  }
  if (insert_at == SIZE_MAX) {  // no IDAT: before IEND, or at the end
    insert_at = kept.size();
    for (std::size_t i = 0; i < kept.size(); ++i)
      if (kept[i].type == "IEND") insert_at = i;
  }
  if (pieces < 1) pieces = 1;
  std::vector<PngChunk> idats;
  const std::size_t piece = compressed.size() / std::size_t(pieces) + 1;
  for (std::size_t at = 0; at < compressed.size() || idats.empty(); at += piece) {
    PngChunk c;
    c.type = "IDAT";
    const std::size_t end = std::min(compressed.size(), at + piece);
    if (at < end) c.data.assign(compressed.begin() + long(at), compressed.begin() + long(end));
    idats.push_back(std::move(c));
  }
  kept.insert(kept.begin() + long(insert_at), idats.begin(), idats.end());
  png->chunks = std::move(kept);
}

}  // namespace plumb::fuzz

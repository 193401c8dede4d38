// libFuzzer target for PngDecoder (drivers/dataset/png_decoder.h), libpng and the libdeflate fast
// path (png_fast_path.h). Random bytes rarely pass a PNG's chunk CRCs and zlib's adler32, so the
// custom mutator below works on the structure: it edits the inflated scanlines, the IHDR fields
// or the chunk list and writes the file back with valid CRCs and a valid zlib stream (a few
// mutations stay raw, to keep testing the checksum errors).
//
// Invariants beyond "no crash", with one decoder and one Mat reused across inputs like a replay:
//  - the header is sane (positive size, 8/16 bits, 1..4 channels);
//  - a decoded image has exactly the header's size, depth and channel count;
//  - when OpenCV's own libpng decoder (cv::imdecode) also decodes the file to the same type,
//    the pixels are equal (catches fast-path unfiltering or channel-order mistakes).
// Images over kMaxDecodedBytes are not decoded: bounding image sizes is a separate task (issue 13).
#include <cstdint>
#include <cstdlib>
#include <map>
#include <string>
#include <random>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "drivers/dataset/png_decoder.h"
#include "fuzz/fuzz_support.h"
#include "fuzz/png_chunks.h"

extern "C" size_t LLVMFuzzerMutate(uint8_t* data, size_t size, size_t max_size);

namespace {

using plumb::fuzz::PngChunk;
using plumb::fuzz::PngFile;
using plumb::fuzz::PngLayout;

constexpr std::size_t kMaxDecodedBytes = 2u << 20;  // a 640x480 BGR frame is 0.9 MiB; larger is slow under ASan
constexpr std::size_t kMaxInflated = 64u << 10;  // the mutator edits scanlines up to this size (keeps it fast)

// libFuzzer's byte mutator on a vector (it may grow the vector up to `max_size`).
void mutateBytes(std::vector<uint8_t>* bytes, std::size_t max_size) {
  const std::size_t size = bytes->size();
  bytes->resize(std::max(max_size, size) + 1);
  const std::size_t n = LLVMFuzzerMutate(bytes->data(), size, std::max(max_size, size));
  bytes->resize(n);
}

// Makes every row's filter byte one of the five valid types (one row in 64 left invalid), so
// mutated scanlines reach the unfiltering code instead of stopping at the first filter byte.
void repairFilterBytes(const PngLayout& layout, std::vector<uint8_t>* filtered, std::mt19937& rng) {
  plumb::fuzz::forEachRow(layout, filtered->size(), [&](std::size_t at) {
    if ((*filtered)[at] > 4 && rng() % 64 != 0) (*filtered)[at] %= 5;
  });
}

// Filtered scanlines of the right size for `layout`: random samples and filter bytes.
std::vector<uint8_t> randomScanlines(const PngLayout& layout, std::mt19937& rng) {
  std::vector<uint8_t> filtered(plumb::fuzz::filteredSize(layout));
  for (uint8_t& b : filtered) b = uint8_t(rng());
  repairFilterBytes(layout, &filtered, rng);
  return filtered;
}

PngLayout randomLayout(std::mt19937& rng) {
  static const int kValid[][2] = {{0, 1}, {0, 2}, {0, 4}, {0, 8}, {0, 16}, {2, 8}, {2, 16}, {3, 1},
                                  {3, 2}, {3, 4}, {3, 8}, {4, 8}, {4, 16}, {6, 8}, {6, 16}};
  const auto& pick = kValid[rng() % (sizeof(kValid) / sizeof(kValid[0]))];
  PngLayout layout;
  layout.colour_type = pick[0];
  layout.bit_depth = pick[1];
  layout.width = 1 + rng() % 40;
  layout.height = 1 + rng() % 40;
  layout.interlace = rng() % 4 == 0 ? 1 : 0;
  return layout;
}

PngChunk chunk(const char* type, std::vector<uint8_t> data) { return PngChunk{type, std::move(data)}; }

std::vector<uint8_t> randomBytes(std::size_t n, std::mt19937& rng) {
  std::vector<uint8_t> bytes(n);
  for (uint8_t& b : bytes) b = uint8_t(rng());
  return bytes;
}

// A whole valid PNG of a random layout (palette images get a PLTE, sometimes a tRNS).
PngFile freshPng(std::mt19937& rng) {
  const PngLayout layout = randomLayout(rng);
  PngFile png;
  png.chunks.push_back(chunk("IHDR", plumb::fuzz::ihdrData(layout)));
  if (layout.colour_type == 3) {
    png.chunks.push_back(chunk("PLTE", randomBytes(3 * (1 + rng() % 256), rng)));
    if (rng() % 2) png.chunks.push_back(chunk("tRNS", randomBytes(1 + rng() % 16, rng)));
  } else if (rng() % 4 == 0 && (layout.colour_type == 0 || layout.colour_type == 2)) {
    png.chunks.push_back(chunk("tRNS", randomBytes(layout.colour_type == 0 ? 2 : 6, rng)));
  }
  png.chunks.push_back(chunk("IEND", {}));
  plumb::fuzz::replaceIdat(&png, randomScanlines(layout, rng), int(rng() % 10), 1 + int(rng() % 3));
  return png;
}

// Edits the inflated scanlines with libFuzzer's byte mutator; mostly kept at the size the
// header implies (so the rows are reached), sometimes a little short or long.
void mutatePixels(PngFile* png, std::mt19937& rng) {
  std::vector<uint8_t> filtered;
  if (!plumb::fuzz::inflateIdat(*png, kMaxInflated, &filtered)) filtered.clear();
  PngLayout layout;
  const std::size_t expected = plumb::fuzz::readLayout(*png, &layout) ? plumb::fuzz::filteredSize(layout) : 0;
  if (filtered.empty() && expected > 0 && expected <= kMaxInflated) filtered = randomScanlines(layout, rng);
  mutateBytes(&filtered, filtered.size() + 16);
  if (rng() % 4 != 0 && expected > 0 && expected <= kMaxInflated) filtered.resize(expected, uint8_t(rng()));
  if (expected > 0 && rng() % 8 != 0) repairFilterBytes(layout, &filtered, rng);
  plumb::fuzz::replaceIdat(png, filtered, int(rng() % 10), 1 + int(rng() % 4));
}

// One IHDR field set to an edge or random value; the scanlines are regenerated for the new layout
// most of the time so the decoder gets past the size check.
void mutateHeader(PngFile* png, std::mt19937& rng) {
  PngLayout layout;
  if (!plumb::fuzz::readLayout(*png, &layout)) return;
  static const uint32_t kSizes[] = {0, 1, 2, 3, 7, 8, 9, 17, 64, 255, 1000000, 1000001, 0x7fffffff, 0x80000000u, 0xffffffffu};
  switch (rng() % 5) {
    case 0: layout.width = rng() % 3 ? 1 + rng() % 64 : kSizes[rng() % 15]; break;
    case 1: layout.height = rng() % 3 ? 1 + rng() % 64 : kSizes[rng() % 15]; break;
    case 2: layout.bit_depth = rng() % 4 ? 1 << (rng() % 5) : int(rng() % 256); break;
    case 3: layout.colour_type = rng() % 4 ? int(rng() % 7) : int(rng() % 256); break;
    case 4: layout.interlace = rng() % 4 ? int(rng() % 2) : int(rng() % 256); break;
  }
  png->chunks[0].data = plumb::fuzz::ihdrData(layout);
  const std::size_t expected = plumb::fuzz::filteredSize(layout);
  if (rng() % 4 != 0 && expected > 0 && expected <= kMaxInflated)
    plumb::fuzz::replaceIdat(png, randomScanlines(layout, rng), int(rng() % 10), 1 + int(rng() % 3));
}

// Chunk list edits: drop, duplicate, swap, insert an ancillary / unknown / misplaced chunk,
// split an IDAT in two.
void mutateLayout(PngFile* png, std::mt19937& rng) {
  auto& c = png->chunks;
  const std::size_t n = c.size();
  switch (rng() % 6) {
    case 0:
      if (n > 1) c.erase(c.begin() + long(rng() % n));
      break;
    case 1: {
      const std::size_t i = rng() % n;
      c.insert(c.begin() + long(rng() % (n + 1)), PngChunk(c[i]));
      break;
    }
    case 2:
      if (n > 1) std::swap(c[rng() % n], c[rng() % n]);
      break;
    case 3: {
      static const char* const kTypes[] = {"tEXt", "gAMA", "tRNS", "PLTE", "bKGD", "sRGB", "iCCP", "zTXt",
                                           "pHYs", "sBIT", "IDAT", "IEND", "IHDR", "abcd", "ABCD", "acTL"};
      PngChunk extra = chunk(kTypes[rng() % 16], randomBytes(rng() % 4 ? rng() % 16 : rng() % 1024, rng));
      c.insert(c.begin() + long(1 + rng() % n), std::move(extra));
      break;
    }
    case 4:
      for (std::size_t i = 0; i < n; ++i) {
        if (c[i].type != "IDAT" || c[i].data.size() < 2) continue;
        const std::size_t cut = 1 + rng() % (c[i].data.size() - 1);
        PngChunk tail = chunk("IDAT", std::vector<uint8_t>(c[i].data.begin() + long(cut), c[i].data.end()));
        c[i].data.resize(cut);
        c.insert(c.begin() + long(i + 1), std::move(tail));
        break;
      }
      break;
    case 5: {  // bytes of one chunk (lengths of PLTE/tRNS/IHDR, text contents), CRC still fixed
      PngChunk& target = c[rng() % n];
      mutateBytes(&target.data, target.data.size() + 64);
      break;
    }
  }
}

}  // namespace

extern "C" size_t LLVMFuzzerCustomMutator(uint8_t* data, size_t size, size_t max_size, unsigned int seed) {
  std::mt19937 rng(seed);
  PngFile png;
  const bool parsed = plumb::fuzz::parsePng(data, size, &png);
  const unsigned choice = rng() % 16;
  if (choice == 0) return LLVMFuzzerMutate(data, size, max_size);  // raw: checksums break
  if (!parsed || choice == 1) {
    png = freshPng(rng);
  } else if (choice < 8) {
    mutatePixels(&png, rng);
  } else if (choice < 11) {
    mutateHeader(&png, rng);
  } else {
    mutateLayout(&png, rng);
  }
  const std::vector<uint8_t> out = plumb::fuzz::writePng(png);
  if (out.size() > max_size) return LLVMFuzzerMutate(data, size, max_size);
  std::memcpy(data, out.data(), out.size());
  return out.size();
}

namespace {

// How far inputs get, printed at exit when PLUMB_FUZZ_STATS is set (does the mutator reach the
// pixels?): headers read, images decoded, of those compared with cv::imdecode.
struct Reach {
  uint64_t inputs = 0, headers = 0, decoded = 0, compared = 0;
  const bool enabled = std::getenv("PLUMB_FUZZ_STATS") != nullptr;
  std::map<std::string, uint64_t> errors;  // decodePixels() failures by message (row numbers cut)
  void failed(const char* message) {
    if (!enabled) return;
    std::string key;  // digits dropped, so "row 3: ... type 9" and "row 4: ... type 7" count together
    for (const char* c = message; *c != '\0' && key.size() < 60; ++c)
      if (*c < '0' || *c > '9') key.push_back(*c);
    ++errors[key];
  }
  ~Reach() {
    if (!enabled) return;
    std::fprintf(stderr, "png reach: %llu inputs, %llu headers, %llu decoded, %llu compared with imdecode\n",
                 (unsigned long long)inputs, (unsigned long long)headers, (unsigned long long)decoded,
                 (unsigned long long)compared);
    for (const auto& [message, count] : errors)
      std::fprintf(stderr, "  %8llu  %s\n", (unsigned long long)count, message.c_str());
  }
} reach;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ++reach.inputs;
  static plumb::PngDecoder decoder;  // reused, as a replay reuses it for every frame
  static cv::Mat image;
  plumb::PngHeader header;
  if (!decoder.readHeader(data, size, &header)) {
    FUZZ_CHECK(decoder.error()[0] != '\0');
    return 0;
  }
  ++reach.headers;
  FUZZ_CHECK(header.width > 0 && header.height > 0);
  FUZZ_CHECK(header.bit_depth == 8 || header.bit_depth == 16);
  FUZZ_CHECK(header.channels >= 1 && header.channels <= 4);
  const std::size_t bytes = std::size_t(header.width) * std::size_t(header.height) * std::size_t(header.channels) *
                            std::size_t(header.bit_depth / 8);
  if (bytes > kMaxDecodedBytes) return 0;
  if (!decoder.decodePixels(image)) {
    FUZZ_CHECK(decoder.error()[0] != '\0');
    reach.failed(decoder.error());
    return 0;
  }
  ++reach.decoded;
  FUZZ_CHECK(image.rows == header.height && image.cols == header.width);
  FUZZ_CHECK(image.channels() == header.channels);
  FUZZ_CHECK(image.depth() == (header.bit_depth == 16 ? CV_16U : CV_8U));

  const cv::Mat reference =
      cv::imdecode(cv::Mat(1, int(size), CV_8U, const_cast<uint8_t*>(data)), cv::IMREAD_UNCHANGED);
  if (!reference.empty() && reference.type() == image.type() && reference.size() == image.size()) {
    ++reach.compared;
    cv::Mat difference;
    cv::absdiff(reference.reshape(1), image.reshape(1), difference);
    FUZZ_CHECK(cv::countNonZero(difference) == 0);
  }
  return 0;
}

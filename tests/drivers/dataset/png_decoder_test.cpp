// PngDecoder (drivers/dataset/png_decoder.h): the pixels cv::imdecode would give, for the layouts
// the TUM loader sees and for ones OpenCV cannot write (interlaced, palette); corruption is an
// error; a second decode into the same Mat allocates nothing (operator new or libpng malloc).
#include <gtest/gtest.h>
#include <png.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "drivers/dataset/png_decoder.h"
#include "platform/allocation_counter.h"

namespace plumb {
namespace {

std::vector<uint8_t> encodePng(const cv::Mat& image) {
  std::vector<uint8_t> bytes;
  EXPECT_TRUE(cv::imencode(".png", image, bytes));
  return bytes;
}

// A PNG written with libpng directly: rows of `row_bytes` each, in PNG's own byte order.
std::vector<uint8_t> writePng(int width, int height, int bit_depth, int colour_type, bool interlaced,
                              const std::vector<std::vector<uint8_t>>& rows,
                              const std::vector<png_color>& palette = {}, int filters = PNG_ALL_FILTERS) {
  std::vector<uint8_t> out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  png_set_write_fn(
      png, &out,
      [](png_structp p, png_bytep data, std::size_t length) {
        auto* v = static_cast<std::vector<uint8_t>*>(png_get_io_ptr(p));
        v->insert(v->end(), data, data + length);
      },
      nullptr);
  png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), bit_depth, colour_type,
               interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  if (!palette.empty()) png_set_PLTE(png, info, palette.data(), int(palette.size()));
  png_set_filter(png, PNG_FILTER_TYPE_BASE, filters);
  png_write_info(png, info);
  std::vector<png_bytep> pointers;
  for (const auto& row : rows) pointers.push_back(const_cast<png_bytep>(row.data()));
  png_write_image(png, pointers.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

bool decode(PngDecoder& decoder, const std::vector<uint8_t>& bytes, cv::Mat& out, PngHeader* header = nullptr) {
  PngHeader h;
  if (!decoder.readHeader(bytes.data(), bytes.size(), &h)) return false;
  if (header != nullptr) *header = h;
  return decoder.decodePixels(out);
}

double maxDifference(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return -1;
  return cv::norm(a, b, cv::NORM_INF);
}

TEST(PngDecoder, SixteenBitDepthAndColourMatchOpenCv) {
  cv::Mat depth(48, 64, CV_16UC1), colour(48, 64, CV_8UC3);
  cv::randu(depth, 0, 65535);
  cv::randu(colour, 0, 255);
  PngDecoder decoder;
  cv::Mat out;
  ASSERT_TRUE(decode(decoder, encodePng(depth), out)) << decoder.error();
  EXPECT_EQ(maxDifference(out, depth), 0.0);
  ASSERT_TRUE(decode(decoder, encodePng(colour), out)) << decoder.error();
  EXPECT_EQ(maxDifference(out, colour), 0.0);  // BGR, like OpenCV
}

TEST(PngDecoder, HeaderReportsWhatTheLoaderChecks) {
  PngDecoder decoder;
  PngHeader h;
  const auto grey8 = encodePng(cv::Mat(6, 10, CV_8UC1, cv::Scalar(7)));
  ASSERT_TRUE(decoder.readHeader(grey8.data(), grey8.size(), &h));
  EXPECT_EQ(h.width, 10);
  EXPECT_EQ(h.height, 6);
  EXPECT_EQ(h.bit_depth, 8);
  EXPECT_EQ(h.channels, 1);
  const auto bgra = encodePng(cv::Mat(3, 4, CV_8UC4, cv::Scalar(1, 2, 3, 4)));
  ASSERT_TRUE(decoder.readHeader(bgra.data(), bgra.size(), &h));
  EXPECT_EQ(h.channels, 4);
}

TEST(PngDecoder, InterlacedSixteenBitGrey) {
  const int w = 13, h = 9;
  std::vector<std::vector<uint8_t>> rows(h, std::vector<uint8_t>(w * 2));
  cv::Mat expected(h, w, CV_16UC1);
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      const uint16_t v = uint16_t(r * 1000 + c * 37 + 1);
      rows[r][c * 2] = uint8_t(v >> 8);  // PNG is big-endian
      rows[r][c * 2 + 1] = uint8_t(v & 0xff);
      expected.at<uint16_t>(r, c) = v;
    }
  }
  PngDecoder decoder;
  cv::Mat out;
  ASSERT_TRUE(decode(decoder, writePng(w, h, 16, PNG_COLOR_TYPE_GRAY, true, rows), out)) << decoder.error();
  EXPECT_EQ(maxDifference(out, expected), 0.0);
}

// Each scanline filter alone (recordings mostly use Sub; encoders may pick any), for 3-byte and
// 2-byte pixels, so every predictor of the decoder is compared against known pixels.
TEST(PngDecoder, EveryFilterTypeDecodesExactly) {
  const int w = 23, h = 11;
  cv::Mat colour(h, w, CV_8UC3), depth(h, w, CV_16UC1);
  cv::randu(colour, 0, 255);
  cv::randu(depth, 0, 65535);
  std::vector<std::vector<uint8_t>> colour_rows(h), depth_rows(h);
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      const cv::Vec3b bgr = colour.at<cv::Vec3b>(r, c);
      colour_rows[r].insert(colour_rows[r].end(), {bgr[2], bgr[1], bgr[0]});  // PNG stores RGB
      const uint16_t v = depth.at<uint16_t>(r, c);
      depth_rows[r].insert(depth_rows[r].end(), {uint8_t(v >> 8), uint8_t(v & 0xff)});
    }
  }
  PngDecoder decoder;
  cv::Mat out;
  for (int filter : {PNG_FILTER_NONE, PNG_FILTER_SUB, PNG_FILTER_UP, PNG_FILTER_AVG, PNG_FILTER_PAETH}) {
    ASSERT_TRUE(decode(decoder, writePng(w, h, 8, PNG_COLOR_TYPE_RGB, false, colour_rows, {}, filter), out))
        << decoder.error();
    EXPECT_EQ(maxDifference(out, colour), 0.0) << "filter " << filter;
    ASSERT_TRUE(decode(decoder, writePng(w, h, 16, PNG_COLOR_TYPE_GRAY, false, depth_rows, {}, filter), out))
        << decoder.error();
    EXPECT_EQ(maxDifference(out, depth), 0.0) << "filter " << filter;
  }
}

TEST(PngDecoder, PaletteExpandsToBgr) {
  const std::vector<png_color> palette = {{10, 20, 30}, {200, 100, 50}};
  std::vector<std::vector<uint8_t>> rows = {{0, 1, 1}, {1, 0, 0}};
  PngDecoder decoder;
  cv::Mat out;
  PngHeader header;
  ASSERT_TRUE(decode(decoder, writePng(3, 2, 8, PNG_COLOR_TYPE_PALETTE, false, rows, palette), out, &header))
      << decoder.error();
  EXPECT_EQ(header.channels, 3);
  ASSERT_EQ(out.type(), CV_8UC3);
  EXPECT_EQ(out.at<cv::Vec3b>(0, 0), cv::Vec3b(30, 20, 10));
  EXPECT_EQ(out.at<cv::Vec3b>(0, 1), cv::Vec3b(50, 100, 200));
}

TEST(PngDecoder, CorruptionIsAnErrorNotNoise) {
  cv::Mat depth(32, 32, CV_16UC1);
  cv::randu(depth, 0, 65535);
  const std::vector<uint8_t> good = encodePng(depth);
  PngDecoder decoder;
  cv::Mat out;
  // A flipped bit in the middle of the file: compressed pixels (CRC / zlib check) or a chunk.
  std::vector<uint8_t> flipped = good;
  flipped[flipped.size() / 2] ^= 0x10;
  EXPECT_FALSE(decode(decoder, flipped, out));
  EXPECT_NE(std::string(decoder.error()).find("corrupt"), std::string::npos) << decoder.error();
  const std::vector<uint8_t> cut(good.begin(), good.begin() + long(good.size() / 2));
  EXPECT_FALSE(decode(decoder, cut, out));
  EXPECT_NE(std::string(decoder.error()).find("truncated"), std::string::npos) << decoder.error();
  const std::vector<uint8_t> text = {'n', 'o', 't', ' ', 'a', ' ', 'p', 'n', 'g', '!'};
  EXPECT_FALSE(decode(decoder, text, out));
  EXPECT_NE(std::string(decoder.error()).find("not a PNG"), std::string::npos) << decoder.error();
  // And the decoder is fine afterwards.
  ASSERT_TRUE(decode(decoder, good, out)) << decoder.error();
  EXPECT_EQ(maxDifference(out, depth), 0.0);
}

// Found by the png_decoder fuzz target: a text chunk whose length field claims 1.8 GB in a file of
// a few dozen bytes made libpng malloc 1.8 GB before finding that the file ends. Now the claim is
// refused against the file's size, from the arena, with a message.
TEST(PngDecoder, ChunkLengthBeyondTheFileIsRefusedWithoutAllocatingIt) {
  std::vector<uint8_t> bytes = encodePng(cv::Mat(1, 1, CV_8UC1, cv::Scalar(9)));
  const std::size_t after_ihdr = 8 + 4 + 4 + 13 + 4;  // signature, IHDR length, type, data, CRC
  const std::vector<uint8_t> huge_text = {0x6e, 0x74, 0x00, 0x00, 't', 'E', 'X', 't', 'C', 'o', 'm', 'm', 0};
  bytes.insert(bytes.begin() + long(after_ihdr), huge_text.begin(), huge_text.end());
  PngDecoder decoder;
  PngHeader header;
  EXPECT_FALSE(decoder.readHeader(bytes.data(), bytes.size(), &header));
  EXPECT_NE(std::string(decoder.error()).find("corrupt"), std::string::npos) << decoder.error();
  EXPECT_EQ(decoder.arenaOverflows(), 0u);  // before the fix: one 1.8 GB malloc
  // The decoder still reads a good file afterwards.
  cv::Mat out;
  ASSERT_TRUE(decode(decoder, encodePng(cv::Mat(2, 3, CV_8UC1, cv::Scalar(4))), out)) << decoder.error();
  EXPECT_EQ(out.at<uint8_t>(1, 2), 4);
}

TEST(PngDecoder, SecondDecodeIntoTheSameMatAllocatesNothing) {
  cv::Mat colour(480, 640, CV_8UC3);
  cv::randu(colour, 0, 255);
  const std::vector<uint8_t> bytes = encodePng(colour);
  PngDecoder decoder;
  cv::Mat out;
  ASSERT_TRUE(decode(decoder, bytes, out));
  const uint64_t before = allocationCount();
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(decode(decoder, bytes, out));
  EXPECT_EQ(allocationCount() - before, 0u);
  EXPECT_EQ(decoder.arenaOverflows(), 0u);  // libpng's own mallocs all came from the arena
  EXPECT_EQ(maxDifference(out, colour), 0.0);
}

}  // namespace
}  // namespace plumb

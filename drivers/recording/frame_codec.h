#pragma once
// Lossless image payloads of a recording frame chunk: raw rows or PNG (see ImageCodec).
// Encoders append to a reused byte buffer; decoders fill caller-owned Mats, which are reused when
// the size matches (PNG decoding uses a per-thread PngDecoder whose arena is reused).
#include <cstddef>
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "drivers/recording/recording_format.h"

namespace plumb {

// `bgr` must be CV_8UC3, `depth_raw` CV_16UC1. Return false only if the encoder fails.
bool encodeColour(const cv::Mat& bgr, ImageCodec codec, int png_compression,
                  std::vector<uint8_t>& out);
bool encodeDepth(const cv::Mat& depth_raw, ImageCodec codec, int png_compression,
                 std::vector<uint8_t>& out);

// Decode into `dst` and check type and size against width x height. False on any mismatch.
bool decodeColour(const uint8_t* bytes, std::size_t size, ImageCodec codec, int width, int height,
                  cv::Mat& dst);
bool decodeDepth(const uint8_t* bytes, std::size_t size, ImageCodec codec, int width, int height,
                 cv::Mat& dst);

}  // namespace plumb

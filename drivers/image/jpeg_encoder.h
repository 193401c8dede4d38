#pragma once
// BGR pixels -> JPEG bytes with libjpeg(-turbo) directly (the viewer's camera image channel,
// viewer/). Optional like the decoder: without libjpeg (PLUMB_HAVE_LIBJPEG unset) encodeJpeg()
// reports "built without libjpeg". Allocates (libjpeg's compressor state and `out`): not for a
// frame path.
#include <cstdint>
#include <string>
#include <vector>

namespace plumb {

// Encodes width x height BGR pixels (rows `stride` bytes apart) at quality 1..100 into *out.
// False with *error set when built without libjpeg or when libjpeg fails.
bool encodeJpeg(const uint8_t* bgr, int width, int height, std::size_t stride, int quality,
                std::vector<uint8_t>* out, std::string* error);

}  // namespace plumb

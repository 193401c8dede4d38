// Texels times a per-texel gain (see texel_gain.h).
#include "drivers/synth/texel_gain.h"

#include <opencv2/core/hal/intrin.hpp>

namespace plumb::synth {
namespace {

#if CV_SIMD128
// 16 channel values times 16 gains: u8 -> f32, multiply, round half to even (v_round, like
// cvRound), pack with saturation (like saturate_cast's clamp: products are never negative).
cv::v_uint8x16 multiply16(const cv::v_uint8x16& values, const cv::v_float32x4 gains[4]) {
  cv::v_uint16x8 low, high;
  cv::v_expand(values, low, high);
  cv::v_uint32x4 quarter[4];
  cv::v_expand(low, quarter[0], quarter[1]);
  cv::v_expand(high, quarter[2], quarter[3]);
  cv::v_int32x4 rounded[4];
  for (int i = 0; i < 4; ++i)
    rounded[i] = cv::v_round(cv::v_cvt_f32(cv::v_reinterpret_as_s32(quarter[i])) * gains[i]);
  return cv::v_pack_u(cv::v_pack(rounded[0], rounded[1]), cv::v_pack(rounded[2], rounded[3]));
}
#endif

}  // namespace

void multiplyTexels(cv::Vec3b* row, const float* gain, int count) {
  int i = 0;
#if CV_SIMD128
  uchar* bytes = reinterpret_cast<uchar*>(row);
  for (; i + 16 <= count; i += 16) {
    cv::v_uint8x16 b, g, r;
    cv::v_load_deinterleave(bytes + 3 * i, b, g, r);
    const cv::v_float32x4 gains[4] = {cv::v_load(gain + i), cv::v_load(gain + i + 4), cv::v_load(gain + i + 8),
                                      cv::v_load(gain + i + 12)};
    cv::v_store_interleave(bytes + 3 * i, multiply16(b, gains), multiply16(g, gains), multiply16(r, gains));
  }
#endif
  for (; i < count; ++i)
    for (int k = 0; k < 3; ++k) row[i][k] = cv::saturate_cast<uchar>(row[i][k] * gain[i]);
}

}  // namespace plumb::synth

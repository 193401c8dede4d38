// Texels times a per-texel gain (see texel_gain.h).
#include "drivers/synth/texel_gain.h"

#include <opencv2/core/hal/intrin.hpp>

namespace plumb::synth {
namespace {

#if CV_SIMD128
// Four bytes times four gains, rounded half to even (v_round, like cvRound).
inline cv::v_int32x4 multiply4(const cv::v_uint32x4& values, const cv::v_float32x4& gains) {
  return cv::v_round(cv::v_cvt_f32(cv::v_reinterpret_as_s32(values)) * gains);
}

// 16 bytes times 16 gains, packed with saturation (like saturate_cast's clamp; products are never
// negative).
inline void multiply16(uchar* values, const cv::v_float32x4& g0, const cv::v_float32x4& g1,
                       const cv::v_float32x4& g2, const cv::v_float32x4& g3) {
  cv::v_uint16x8 low, high;
  cv::v_expand(cv::v_load(values), low, high);
  cv::v_uint32x4 q0, q1, q2, q3;
  cv::v_expand(low, q0, q1);
  cv::v_expand(high, q2, q3);
  cv::v_store(values, cv::v_pack_u(cv::v_pack(multiply4(q0, g0), multiply4(q1, g1)),
                                   cv::v_pack(multiply4(q2, g2), multiply4(q3, g3))));
}

// The gains of four texels [a b c d] as the gains of their twelve channels:
// [a a a b], [b b c c], [c d d d].
inline void perChannel(const cv::v_float32x4& gains, cv::v_float32x4 out[3]) {
  cv::v_float32x4 pairs_low, pairs_high;  // [a a b b], [c c d d]
  cv::v_zip(gains, gains, pairs_low, pairs_high);
  out[0] = cv::v_combine_low(pairs_low, gains);
  out[1] = cv::v_extract<2>(pairs_low, pairs_high);
  out[2] = cv::v_combine_high(gains, pairs_high);
}
#endif

}  // namespace

void multiplyTexels(cv::Vec3b* row, const float* gain, int count) {
  int i = 0;
#if CV_SIMD128
  // 16 texels at a time, as 48 bytes times 48 gains (each texel's gain three times): cheaper than
  // de-interleaving the channels, which SSE2 has no byte shuffle for.
  uchar* bytes = reinterpret_cast<uchar*>(row);
  for (; i + 16 <= count; i += 16) {
    cv::v_float32x4 g[12];
    for (int j = 0; j < 4; ++j) perChannel(cv::v_load(gain + i + 4 * j), g + 3 * j);
    uchar* block = bytes + 3 * i;
    multiply16(block, g[0], g[1], g[2], g[3]);
    multiply16(block + 16, g[4], g[5], g[6], g[7]);
    multiply16(block + 32, g[8], g[9], g[10], g[11]);
  }
#endif
  for (; i < count; ++i)
    for (int k = 0; k < 3; ++k) row[i][k] = cv::saturate_cast<uchar>(row[i][k] * gain[i]);
}

}  // namespace plumb::synth

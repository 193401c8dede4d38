#pragma once
// Multiplying texels by a gain, the inner loop of texture shading and light baking.
#include <opencv2/core.hpp>

namespace plumb::synth {

// row[i][k] = saturate_cast<uchar>(row[i][k] * gain[i]) for i < count and the three channels k:
// the float product rounded half to even and clamped to 0..255. SIMD (OpenCV universal
// intrinsics: SSE2 or NEON) with a scalar tail; bit-identical to the scalar formula.
void multiplyTexels(cv::Vec3b* row, const float* gain, int count);

}  // namespace plumb::synth

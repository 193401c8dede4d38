#include "pipeline/image_pyramid.h"

#include <cmath>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

namespace plumb {

ImagePyramid::ImagePyramid(int width, int height, int num_levels, float scale_factor)
    : num_levels_(num_levels < 1 ? 1 : (num_levels > kPyramidLevels ? kPyramidLevels : num_levels)) {
  std::array<cv::Size, kPyramidLevels> sizes;
  int total_rows = 0;
  for (int i = 0; i < num_levels_; ++i) {
    scales_[i] = std::pow(scale_factor, static_cast<float>(i));
    sizes[i] = cv::Size(static_cast<int>(std::lround(width / scales_[i])),
                        static_cast<int>(std::lround(height / scales_[i])));
    total_rows += sizes[i].height;
  }
  row_filtered_.create(1, width + 6, CV_16UC1);  // one padded row
  const cv::Mat kernel = cv::getGaussianKernel(7, 2.0, CV_64F);
  int sum = 0;
  for (int k = 0; k < 7; ++k) sum += kernel_[k] = static_cast<int>(std::lround(kernel.at<double>(k) * 256));
  kernel_[3] += 256 - sum;  // exact unit gain
  buffer_.create(total_rows, width, CV_8UC1);
  blurred_buffer_.create(total_rows, width, CV_8UC1);
  buffer_.setTo(0);
  blurred_buffer_.setTo(0);
  int row = 0;
  for (int i = 0; i < num_levels_; ++i) {
    const cv::Rect roi(0, row, sizes[i].width, sizes[i].height);
    levels_[i] = buffer_(roi);
    blurred_levels_[i] = blurred_buffer_(roi);
    row += sizes[i].height;
  }
}

void ImagePyramid::build(const cv::Mat& grey) {
  grey.copyTo(levels_[0]);  // levels_[0] has the right size: copyTo writes in place
  for (int i = 1; i < num_levels_; ++i) {
    // Resize from the previous level (as ORB-SLAM does): cheap, and the 1.2 step keeps
    // bilinear aliasing small. dst already has its size, so OpenCV writes into the ROI.
    cv::resize(levels_[i - 1], levels_[i], levels_[i].size(), 0, 0, cv::INTER_LINEAR);
  }
  // 7x7, sigma 2: the smoothing rotated BRIEF is defined on.
  for (int i = 0; i < num_levels_; ++i) blur(levels_[i], blurred_levels_[i]);
}

void ImagePyramid::blur(const cv::Mat& src, cv::Mat& dst) {
  // Separable, vertical pass first, 8.8 fixed point: the vertical sum (<= 255 * 256) is rounded
  // back to 8 bits of range so the horizontal pass also fits 16-bit lanes (the lost fraction is far
  // below what the binary tests can see). One padded 16-bit row buffer, reflected borders.
  const int w = src.cols, h = src.rows;
  auto reflect = [](int i, int n) { return i < 0 ? -i : (i >= n ? 2 * n - 2 - i : i); };  // REFLECT_101
  uint16_t* t = row_filtered_.ptr<uint16_t>(0) + 3;  // t[-3 .. w+2] valid after padding
  const uint16_t k[7] = {uint16_t(kernel_[0]), uint16_t(kernel_[1]), uint16_t(kernel_[2]), uint16_t(kernel_[3]),
                         uint16_t(kernel_[4]), uint16_t(kernel_[5]), uint16_t(kernel_[6])};
  cv::v_uint16x8 vk[7];
  for (int i = 0; i < 7; ++i) vk[i] = cv::v_setall_u16(k[i]);
  const cv::v_uint16x8 half = cv::v_setall_u16(128);
  for (int y = 0; y < h; ++y) {
    const uint8_t* r[7];
    for (int i = 0; i < 7; ++i) r[i] = src.ptr<uint8_t>(reflect(y + i - 3, h));
    int x = 0;
    for (; x + 16 <= w; x += 16) {
      cv::v_uint16x8 lo = cv::v_setzero_u16(), hi = cv::v_setzero_u16();
      for (int i = 0; i < 7; ++i) {
        cv::v_uint16x8 a, b;
        cv::v_expand(cv::v_load(r[i] + x), a, b);
        lo += cv::v_mul_wrap(a, vk[i]);  // the sum stays <= 65280: no overflow
        hi += cv::v_mul_wrap(b, vk[i]);
      }
      cv::v_store(t + x, (lo + half) >> 8);
      cv::v_store(t + x + 8, (hi + half) >> 8);
    }
    for (; x < w; ++x) {
      unsigned acc = 0;
      for (int i = 0; i < 7; ++i) acc += k[i] * r[i][x];
      t[x] = static_cast<uint16_t>((acc + 128) >> 8);
    }
    for (int i = 1; i <= 3; ++i) {
      t[-i] = t[reflect(-i, w)];
      t[w - 1 + i] = t[reflect(w - 1 + i, w)];
    }
    uint8_t* d = dst.ptr<uint8_t>(y);
    x = 0;
    for (; x + 8 <= w; x += 8) {
      cv::v_uint16x8 acc = cv::v_setzero_u16();
      for (int i = 0; i < 7; ++i) acc += cv::v_mul_wrap(cv::v_load(t + x + i - 3), vk[i]);
      cv::v_pack_store(d + x, (acc + half) >> 8);
    }
    for (; x < w; ++x) {
      unsigned acc = 0;
      for (int i = 0; i < 7; ++i) acc += k[i] * t[x + i - 3];
      d[x] = static_cast<uint8_t>((acc + 128) >> 8);
    }
  }
}

}  // namespace plumb

#include "pipeline/image_pyramid.h"

#include <cmath>

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
  row_filtered_.create(height, width, CV_16UC1);
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
  const int w = src.cols, h = src.rows;
  const int k0 = kernel_[0], k1 = kernel_[1], k2 = kernel_[2], k3 = kernel_[3];  // symmetric
  auto reflect = [](int i, int n) { return i < 0 ? -i : (i >= n ? 2 * n - 2 - i : i); };  // REFLECT_101
  for (int y = 0; y < h; ++y) {
    const uint8_t* s = src.ptr<uint8_t>(y);
    uint16_t* t = row_filtered_.ptr<uint16_t>(y);
    for (int x = 0; x < 3; ++x) {
      int acc = 0;
      for (int k = -3; k <= 3; ++k) acc += kernel_[k + 3] * s[reflect(x + k, w)];
      t[x] = static_cast<uint16_t>(acc);
    }
    for (int x = 3; x < w - 3; ++x) {  // interior: plain loop the compiler vectorises
      t[x] = static_cast<uint16_t>(k0 * (s[x - 3] + s[x + 3]) + k1 * (s[x - 2] + s[x + 2]) +
                                   k2 * (s[x - 1] + s[x + 1]) + k3 * s[x]);
    }
    for (int x = std::max(3, w - 3); x < w; ++x) {
      int acc = 0;
      for (int k = -3; k <= 3; ++k) acc += kernel_[k + 3] * s[reflect(x + k, w)];
      t[x] = static_cast<uint16_t>(acc);
    }
  }
  for (int y = 0; y < h; ++y) {
    const uint16_t* r[7];
    for (int k = -3; k <= 3; ++k) r[k + 3] = row_filtered_.ptr<uint16_t>(reflect(y + k, h));
    uint8_t* d = dst.ptr<uint8_t>(y);
    for (int x = 0; x < w; ++x) {
      const uint32_t acc = k0 * (uint32_t(r[0][x]) + r[6][x]) + k1 * (uint32_t(r[1][x]) + r[5][x]) +
                           k2 * (uint32_t(r[2][x]) + r[4][x]) + k3 * uint32_t(r[3][x]);
      d[x] = static_cast<uint8_t>((acc + 32768) >> 16);
    }
  }
}

}  // namespace plumb

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
  for (int i = 0; i < num_levels_; ++i) {
    // 7x7, sigma 2: the smoothing rotated BRIEF is defined on. BORDER_ISOLATED keeps the filter
    // from reading the neighbouring levels stacked in the same buffer.
    cv::GaussianBlur(levels_[i], blurred_levels_[i], cv::Size(7, 7), 2, 2,
                     cv::BORDER_REFLECT_101 | cv::BORDER_ISOLATED);
  }
}

}  // namespace plumb

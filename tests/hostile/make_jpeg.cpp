// Test helper of the hostile-input suite (tests/hostile/hostile_suite.py): writes a textured
// 8-bit colour JPEG of the given size, so a dataset can hold JPEG colour images (then truncated by
// the suite). OpenCV's imgcodecs is a test-only dependency (docs/EMBEDDED.md).
// Usage: plumb_hostile_jpeg OUT.jpg WIDTH HEIGHT
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: plumb_hostile_jpeg OUT.jpg WIDTH HEIGHT\n");
    return 2;
  }
  const int width = std::atoi(argv[2]), height = std::atoi(argv[3]);
  if (width < 8 || height < 8 || width > 8192 || height > 8192) {
    std::fprintf(stderr, "plumb_hostile_jpeg: size out of range\n");
    return 2;
  }
  cv::Mat image(height, width, CV_8UC3);
  cv::RNG rng(7);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);  // noise: a large file, so a cut loses many rows
  const std::vector<int> params = {cv::IMWRITE_JPEG_QUALITY, 95};
  if (!cv::imwrite(argv[1], image, params)) {
    std::fprintf(stderr, "plumb_hostile_jpeg: cannot write %s\n", argv[1]);
    return 1;
  }
  return 0;
}

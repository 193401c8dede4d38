// plumb_bench_stock_frontend: plumb's front end next to the stock OpenCV path (cv::ORB 1000/8/1.2 +
// line_descriptor::LSDDetector + BinaryDescriptor) on the same frames of a TUM-layout folder, one
// thread. It lives here, not in `plumb bench frontend`, so that only this program links
// libopencv_features2d and libopencv_line_descriptor (docs/EMBEDDED.md: the product links core and
// imgproc only).
//   plumb_bench_stock_frontend --dataset DIR [--camera tum1] [--frames N] [--clock wall|cpu]
// The last two lines are the machine-readable summary:
//   frontend_ms_median X
//   stock_opencv_ms_median Y
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/line_descriptor.hpp>

#include "drivers/dataset/camera_presets.h"
#include "drivers/dataset/tum_dataset.h"
#include "pipeline/frontend/feature_extractor.h"
#include "platform/stage_timing.h"

namespace {

using plumb::StageClock;
using plumb::TimingSeries;
using plumb::msSince;
using plumb::threadCpuMs;
constexpr int kNameWidth = 26;

// cv::ORB 1000 features, 8 levels, 1.2, and the contrib LSDDetector + BinaryDescriptor (LBD) on
// every detected line.
struct StockPath {
  cv::Ptr<cv::ORB> orb = cv::ORB::create(1000, 1.2f, 8);
  cv::Ptr<cv::line_descriptor::LSDDetector> lsd = cv::line_descriptor::LSDDetector::createLSDDetector();
  cv::Ptr<cv::line_descriptor::BinaryDescriptor> lbd = cv::line_descriptor::BinaryDescriptor::createBinaryDescriptor();
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors, line_descriptors, grey;
  std::vector<cv::line_descriptor::KeyLine> keylines;
  double orb_ms = 0, lsd_ms = 0, lbd_ms = 0;              // wall
  double orb_cpu_ms = 0, lsd_cpu_ms = 0, lbd_cpu_ms = 0;  // thread CPU time

  void run(const cv::Mat& bgr) {
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    auto t = StageClock::now();
    double cpu = threadCpuMs();
    orb->detectAndCompute(grey, cv::noArray(), keypoints, descriptors);
    orb_ms = msSince(t);
    orb_cpu_ms = threadCpuMs() - cpu;
    t = StageClock::now();
    cpu = threadCpuMs();
    keylines.clear();
    lsd->detect(grey, keylines, 2, 1);
    lsd_ms = msSince(t);
    lsd_cpu_ms = threadCpuMs() - cpu;
    t = StageClock::now();
    cpu = threadCpuMs();
    lbd->compute(grey, keylines, line_descriptors);
    lbd_ms = msSince(t);
    lbd_cpu_ms = threadCpuMs() - cpu;
  }
};

const char* argValue(int argc, char** argv, const char* name, const char* fallback) {
  for (int i = 1; i + 1 < argc; ++i)
    if (std::strcmp(argv[i], name) == 0) return argv[i + 1];
  return fallback;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace plumb;
  const char* dataset = argValue(argc, argv, "--dataset", nullptr);
  if (dataset == nullptr) {
    std::fprintf(stderr,
                 "usage: plumb_bench_stock_frontend --dataset DIR [--camera tum1] [--frames N] [--clock wall|cpu]\n");
    return 2;
  }
  const long max_frames = std::atol(argValue(argc, argv, "--frames", "-1"));
  const bool cpu_clock = std::string(argValue(argc, argv, "--clock", "wall")) == "cpu";
  PinholeCamera camera;
  Status st = cameraFromSpec(argValue(argc, argv, "--camera", "tum1"), &camera);
  std::unique_ptr<TumDatasetSource> source;
  if (st.ok()) st = TumDatasetSource::open(dataset, camera, &source);
  if (!st.ok()) {
    std::fprintf(stderr, "plumb_bench_stock_frontend: %s\n", st.message().c_str());
    return 1;
  }
  cv::setNumThreads(1);  // single thread, for both paths
  FeatureExtractor extractor(camera, ExtractorOptions{});
  auto features = std::make_unique<FrameFeatures>();
  StockPath stock;
  TimingSeries total{"plumb frontend total", {}}, cpu_total{"plumb frontend (CPU)", {}};
  TimingSeries s_orb{"stock cv::ORB", {}}, s_lsd{"stock LSDDetector", {}}, s_lbd{"stock BinaryDescriptor", {}},
      s_total{"stock total", {}};
  TimingSeries s_cpu_orb{"stock cv::ORB (CPU)", {}}, s_cpu_lsd{"stock LSDDetector (CPU)", {}},
      s_cpu_lbd{"stock BinaryDesc. (CPU)", {}}, s_cpu_total{"stock total (CPU)", {}};
  double sum_stock_lines = 0;
  RgbdImage frame;
  const size_t n = max_frames > 0 ? std::min<size_t>(source->size(), max_frames) : source->size();
  for (size_t i = 0; i < n; ++i) {
    st = source->load(i, frame);
    if (!st.ok() || !extractor.extract(frame, *features)) {
      std::fprintf(stderr, "plumb_bench_stock_frontend: frame %zu: %s\n", i,
                   st.ok() ? "does not match the camera size" : st.message().c_str());
      return 1;
    }
    total.ms.push_back(extractor.lastTimings().total_ms);
    cpu_total.ms.push_back(extractor.lastTimings().total_cpu_ms);
    const auto t0 = StageClock::now();
    const double cpu0 = threadCpuMs();
    stock.run(frame.bgr);
    s_total.ms.push_back(msSince(t0));
    s_cpu_total.ms.push_back(threadCpuMs() - cpu0);
    s_orb.ms.push_back(stock.orb_ms);
    s_lsd.ms.push_back(stock.lsd_ms);
    s_lbd.ms.push_back(stock.lbd_ms);
    s_cpu_orb.ms.push_back(stock.orb_cpu_ms);
    s_cpu_lsd.ms.push_back(stock.lsd_cpu_ms);
    s_cpu_lbd.ms.push_back(stock.lbd_cpu_ms);
    sum_stock_lines += stock.keylines.size();
  }
  std::printf("plumb_bench_stock_frontend: %zu frames of %s, 1 thread\n", n, dataset);
  std::printf("  stock path: %.0f lines described per frame\n", sum_stock_lines / std::max<size_t>(n, 1));
  for (const TimingSeries* s : {&total, &cpu_total, &s_orb, &s_lsd, &s_lbd, &s_total, &s_cpu_orb, &s_cpu_lsd, &s_cpu_lbd,
                          &s_cpu_total})
    s->print(kNameWidth);
  std::printf("  speed-up (stock / plumb, medians): wall %.1fx, CPU %.1fx\n",
              s_total.percentile(0.5) / total.percentile(0.5), s_cpu_total.percentile(0.5) / cpu_total.percentile(0.5));
  std::printf("summary clock: %s\n", cpu_clock ? "thread CPU time" : "wall (steady clock)");
  std::printf("frontend_ms_median %.2f\n", (cpu_clock ? cpu_total : total).percentile(0.5));
  std::printf("stock_opencv_ms_median %.2f\n", (cpu_clock ? s_cpu_total : s_total).percentile(0.5));
  return 0;
}

// plumb profile trace.json [--png hist.png]: reads a trace written by `plumb run --profile`, prints
// the latency table (p50/p90/p99/max per stage and end to end, dropped frames, frames per second)
// and optionally draws one latency histogram per stage into a PNG.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "drivers/image/png_encoder.h"
#include "runtime/chrome_trace.h"
#include "runtime/run_report.h"
#include "tools/args.h"
#include "tools/command.h"
#include "tools/io_plan.h"

namespace plumb::tools {
namespace {

using runtime::LatencyHistogram;

constexpr int kPanelWidth = 900;
constexpr int kPanelHeight = 170;
constexpr int kMarginLeft = 60;
constexpr int kMarginBottom = 30;

std::string formatMs(int64_t ns) {
  char buf[32];
  const double ms = static_cast<double>(ns) * 1e-6;
  std::snprintf(buf, sizeof(buf), ms < 1.0 ? "%.2f ms" : "%.1f ms", ms);
  return buf;
}

// Bins [first, last] that contain data in any histogram, padded by one, so the x axis is shared.
void occupiedBinRange(const runtime::RunReport& report, int* first, int* last) {
  *first = LatencyHistogram::kBinCount;
  *last = -1;
  auto scan = [&](const LatencyHistogram& h) {
    for (int b = 0; b < LatencyHistogram::kBinCount; ++b) {
      if (h.binCount(b) == 0) continue;
      *first = std::min(*first, b);
      *last = std::max(*last, b);
    }
  };
  for (const auto& stage : report.stages) scan(stage.latency);
  scan(report.end_to_end);
  if (*last < 0) {
    *first = 0;
    *last = LatencyHistogram::kBinCount - 1;
    return;
  }
  *first = std::max(0, *first - 1);
  *last = std::min(LatencyHistogram::kBinCount - 1, *last + 1);
}

void drawPanel(cv::Mat& canvas, int top, const std::string& title, const LatencyHistogram& h,
               int first_bin, int last_bin) {
  const cv::Scalar kInk(40, 40, 40);
  const int plot_w = kPanelWidth - kMarginLeft - 20;
  const int plot_h = kPanelHeight - kMarginBottom - 30;
  const int x0 = kMarginLeft;
  const int y_base = top + 30 + plot_h;
  const int bins = last_bin - first_bin + 1;
  const double bar_w = static_cast<double>(plot_w) / bins;
  uint64_t peak = 1;
  for (int b = first_bin; b <= last_bin; ++b) peak = std::max(peak, h.binCount(b));

  std::string label = title + "   n=" + std::to_string(h.count());
  if (h.count() > 0) {
    label += "  p50 " + formatMs(h.percentileNs(0.5)) + "  p99 " + formatMs(h.percentileNs(0.99)) +
             "  max " + formatMs(h.maxNs());
  }
  cv::putText(canvas, label, {x0, top + 20}, cv::FONT_HERSHEY_SIMPLEX, 0.5, kInk, 1, cv::LINE_AA);
  cv::line(canvas, {x0, y_base}, {x0 + plot_w, y_base}, kInk);
  for (int b = first_bin; b <= last_bin; ++b) {
    const uint64_t n = h.binCount(b);
    const int x = x0 + static_cast<int>((b - first_bin) * bar_w);
    if (n > 0) {
      const int bar_h = std::max(1, static_cast<int>(plot_h * static_cast<double>(n) / peak));
      cv::rectangle(canvas, {x + 1, y_base - bar_h}, {x + std::max(2, static_cast<int>(bar_w)) - 1, y_base},
                    cv::Scalar(180, 110, 40), cv::FILLED);
    }
  }
  // Decade ticks on the shared log axis: 10 us, 100 us, 1 ms, ...
  for (int b = first_bin; b <= last_bin; ++b) {
    if (b < 1 || (b - 1) % LatencyHistogram::kBinsPerDecade != 0) continue;
    const int x = x0 + static_cast<int>((b - first_bin) * bar_w);
    cv::line(canvas, {x, y_base}, {x, y_base + 5}, kInk);
    cv::putText(canvas, formatMs(LatencyHistogram::binLowerNs(b)), {x - 20, y_base + 20},
                cv::FONT_HERSHEY_SIMPLEX, 0.4, kInk, 1, cv::LINE_AA);
  }
}

Status drawHistograms(const runtime::RunReport& report, const std::string& path) {
  int first = 0;
  int last = 0;
  occupiedBinRange(report, &first, &last);
  const int panels = static_cast<int>(report.stages.size()) + 1;
  cv::Mat canvas(panels * kPanelHeight, kPanelWidth, CV_8UC3, cv::Scalar(255, 255, 255));
  for (int i = 0; i < panels - 1; ++i) {
    drawPanel(canvas, i * kPanelHeight, report.stages[i].name, report.stages[i].latency, first, last);
  }
  drawPanel(canvas, (panels - 1) * kPanelHeight, "end-to-end", report.end_to_end, first, last);
  return writePngOutput(path, canvas, pngFastestOptions());
}

int profileCommand(int argc, char** argv) {
  Args args(argc, argv, {"png"}, {});
  if (args.help() || args.positional().size() != 1 || !args.error().empty()) {
    if (!args.error().empty()) std::fprintf(stderr, "plumb profile: %s\n", args.error().c_str());
    std::fprintf(stderr,
                 "usage: plumb profile TRACE.json [--png HIST.png]\n"
                 "  Reads a Chrome trace written by `plumb run --profile`, prints p50/p90/p99/max\n"
                 "  latency per stage and end to end, dropped frames and frames per second.\n"
                 "  --png  also draw one latency histogram per stage (log time axis)\n");
    return args.help() ? 0 : 2;
  }
  // The histogram never overwrites the trace (or a link to it), and its folder must take it.
  IoPlan io;
  io.addInput(args.positional()[0]);
  io.addOutput("--png", args.get("png"));
  const Status io_status = io.check();
  if (!io_status.ok()) {
    std::fprintf(stderr, "plumb profile: %s\n", io_status.message().c_str());
    return 2;
  }
  runtime::RunReport report;
  const Status status = runtime::readChromeTrace(args.positional()[0], &report);
  if (!status.ok()) {
    std::fprintf(stderr, "plumb profile: %s\n", status.message().c_str());
    return 1;
  }
  std::printf("%s", runtime::formatRunReport(report).c_str());
  if (args.has("png")) {
    const Status drawn = drawHistograms(report, args.get("png"));
    if (!drawn.ok()) {
      std::fprintf(stderr, "plumb profile: %s\n", drawn.message().c_str());
      return 1;
    }
    std::printf("histograms: %s\n", args.get("png").c_str());
  }
  return 0;
}

}  // namespace

PLUMB_COMMAND(profile, "latency table and histograms of a --profile trace", profileCommand);

}  // namespace plumb::tools

// plumb_bench_viewer [DATASET] [--repeat N] [--clients K] [--rt-priority P]
// What watching a run costs the run (docs/VIEWER.md "Cost"), measured as same-run ratios:
//   1. --mode realtime at the recorded rate, alternately without a viewer and with `--serve` and K
//      clients (websocketpp, in this process, subscribed to every channel and reading): the p99
//      sensor-to-pose latency of each (median of N runs) and their ratio (target <= 1.05), drops;
//   2. --mode fast with the viewer and K clients: trajectory bytes equal to without, heap
//      allocations per frame after warm-up on the run's threads (the viewer thread's own are
//      counted apart: platform/allocation_counter.h).
// DATASET: a TUM folder or source spec; default fr1/rpy head250 from ../shared/datasets when
// present, else synth:textured:1:300. Wall-clock numbers need a quiet machine; the ratio is what
// is compared.
#define ASIO_STANDALONE
#define _WEBSOCKETPP_CPP11_STL_
#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "drivers/common/source_capture.h"
#include "drivers/open/open_source.h"
#include "drivers/trajectory/trajectory_io.h"
#include "pipeline/run/odometry_run.h"
#include "platform/allocation_counter.h"
#include "viewer/run_viewer.h"

namespace plumb {
namespace {

using WsClient = websocketpp::client<websocketpp::config::asio_client>;

// One viewer: subscribes to every advertised channel and reads everything, on its own thread.
class BenchClient {
 public:
  explicit BenchClient(int port) {
    client_.clear_access_channels(websocketpp::log::alevel::all);
    client_.clear_error_channels(websocketpp::log::elevel::all);
    client_.init_asio();
    client_.set_message_handler([this](websocketpp::connection_hdl h, WsClient::message_ptr m) {
      bytes_ += m->get_payload().size();
      if (m->get_opcode() != websocketpp::frame::opcode::text) return;
      const std::string& text = m->get_payload();
      if (text.find("\"op\":\"advertise\"") == std::string::npos) return;
      std::string subscribe = R"({"op":"subscribe","subscriptions":[)";
      for (int id = 1; id <= 10; ++id) {
        subscribe += (id > 1 ? "," : "") + std::string(R"({"id":)") + std::to_string(id) + R"(,"channelId":)" +
                     std::to_string(id) + "}";
      }
      subscribe += "]}";
      websocketpp::lib::error_code ec;
      client_.send(h, subscribe, websocketpp::frame::opcode::text, ec);
      subscribed_ = true;
    });
    websocketpp::lib::error_code ec;
    WsClient::connection_ptr con = client_.get_connection("ws://127.0.0.1:" + std::to_string(port) + "/", ec);
    con->add_subprotocol("foxglove.websocket.v1");
    client_.connect(con);
    // A viewer is another process in real use: its allocations are not the run's.
    thread_ = std::thread([this] {
      excludeThisThreadFromAllocationCount();
      client_.run();
    });
  }
  ~BenchClient() {
    client_.stop();
    thread_.join();
  }
  bool subscribed() const { return subscribed_; }
  uint64_t bytes() const { return bytes_; }

 private:
  WsClient client_;
  std::thread thread_;
  std::atomic<bool> subscribed_{false};
  std::atomic<uint64_t> bytes_{0};
};

// Keeps the output trajectory as TUM text (compared byte for byte).
class TextSink final : public OdometrySink {
 public:
  TextSink() { text.reserve(std::size_t(4) << 20); }  // no growth during the run: 0 allocations
  Status onFinishedFrame(const FinishedFrame& f) override {
    char line[kTumLineCapacity];
    formatTumLine(toStampedPose(f), line, sizeof(line));
    text += line;
    text += '\n';
    return Status::Ok();
  }
  std::string text;
};

struct RunNumbers {
  double p99_ms = 0;
  uint64_t dropped = 0, late = 0;
  double allocations_per_frame = 0;
  uint64_t client_bytes = 0;
  std::string trajectory;
  std::string viewer_summary;
};

void check(const Status& s) {
  if (!s.ok()) {
    std::fprintf(stderr, "plumb_bench_viewer: %s\n", s.message().c_str());
    std::exit(1);
  }
}

RunNumbers runOnce(const std::string& dataset, runtime::RunMode mode, int clients, int rt_priority) {
  std::unique_ptr<FrameSource> source;
  check(openFrameSource(dataset, "", &source));
  OdometryRunOptions options;
  options.schedule.mode = mode;
  options.schedule.realtime_priority = rt_priority;
  TextSink outputs;
  std::unique_ptr<viewer::RunViewer> viewer;
  std::vector<std::unique_ptr<BenchClient>> watching;
  if (clients > 0) {
    viewer::ServeAddress address;  // 127.0.0.1, any free port
    check(viewer::RunViewer::start(address, viewer::LiveViewOptions{"bench", dataset}, &viewer));
    for (int i = 0; i < clients; ++i) watching.push_back(std::make_unique<BenchClient>(viewer->port()));
    for (int wait = 0; wait < 500; ++wait) {
      bool all = true;
      for (const auto& c : watching) all = all && c->subscribed();
      if (all) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  OdometryRunResult result;
  SourceCapture capture(*source);
  check(runOdometry(capture, SystemOptions{}, viewer ? viewer->wrap(outputs) : outputs, options, &result));
  RunNumbers n;
  if (viewer) {
    viewer->stop(1.0);
    n.viewer_summary = viewer->summary();
    for (const auto& c : watching) n.client_bytes += c->bytes();
  }
  n.p99_ms = double(result.report.end_to_end.percentileNs(0.99)) * 1e-6;
  n.dropped = result.report.frames_dropped;
  n.late = result.report.frames_late;
  n.allocations_per_frame =
      result.allocation_frames > 0 ? double(result.allocations_after_warmup) / double(result.allocation_frames) : -1;
  n.trajectory = std::move(outputs.text);
  return n;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

}  // namespace
}  // namespace plumb

int main(int argc, char** argv) {
  using namespace plumb;
  std::string dataset = std::string(PLUMB_DATASETS_DIR) + "/tum_fr1_rpy_head250";
  int repeat = 3, clients = 1, rt_priority = 0;
  bool dataset_given = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--repeat" && i + 1 < argc) {
      repeat = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--clients" && i + 1 < argc) {
      clients = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--rt-priority" && i + 1 < argc) {
      rt_priority = std::atoi(argv[++i]);
    } else if (a == "--help" || a == "-h") {
      std::printf("usage: plumb_bench_viewer [DATASET] [--repeat N] [--clients K] [--rt-priority P]\n");
      return 0;
    } else {
      dataset = a;
      dataset_given = true;
    }
  }
  if (!dataset_given) {
    std::FILE* f = std::fopen((dataset + "/rgb.txt").c_str(), "r");
    if (f != nullptr) {
      std::fclose(f);
    } else {
      dataset = "synth:textured:1:300";
    }
  }
  std::printf("dataset %s, %d client(s), %d repeat(s)%s\n", dataset.c_str(), clients, repeat,
              rt_priority > 0 ? ", SCHED_FIFO stage threads" : "");

  std::vector<double> without, with;
  for (int r = 0; r < repeat; ++r) {
    // Alternating order: a machine that gets busier or quieter over time favours neither side.
    for (int k = 0; k < 2; ++k) {
      const bool viewer = (r + k) % 2 == 1;
      const RunNumbers n = runOnce(dataset, runtime::RunMode::kRealtime, viewer ? clients : 0, rt_priority);
      (viewer ? with : without).push_back(n.p99_ms);
      std::printf("realtime run %d %s viewer: p99 sensor-to-pose %.2f ms, dropped %llu, late %llu%s%s\n", r + 1,
                  viewer ? "with   " : "without", n.p99_ms, (unsigned long long)n.dropped, (unsigned long long)n.late,
                  viewer ? (", clients received " + std::to_string(n.client_bytes / 1024) + " KiB\n  ").c_str() : "",
                  viewer ? n.viewer_summary.c_str() : "");
    }
  }
  const double p99_without = median(without), p99_with = median(with);
  std::printf("realtime_p99_with_over_without %.3f (median of %d: %.2f / %.2f ms; target <= 1.05)\n",
              p99_with / p99_without, repeat, p99_with, p99_without);

  const RunNumbers plain = runOnce(dataset, runtime::RunMode::kFast, 0, rt_priority);
  const RunNumbers served = runOnce(dataset, runtime::RunMode::kFast, clients, rt_priority);
  std::printf("fast_trajectory_identical_with_viewer %s (%zu bytes)\n",
              plain.trajectory == served.trajectory ? "yes" : "NO", plain.trajectory.size());
  std::printf("fast_allocations_per_frame without %.2f, with viewer %.2f (run threads; %s)\n",
              plain.allocations_per_frame, served.allocations_per_frame, served.viewer_summary.c_str());
  return plain.trajectory == served.trajectory ? 0 : 1;
}

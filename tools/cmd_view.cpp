// plumb view: serve a finished run to Foxglove/Lichtblick and to plumb's own page (docs/VIEWER.md):
// its trajectory, optionally ground truth beside it (aligned, error-coloured), its map file
// (keyframes, loop edges, points, lines) and statistics. Serves until SIGINT/SIGTERM.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "drivers/trajectory/trajectory_io.h"
#include "tools/args.h"
#include "tools/command.h"
#include "tools/map_files.h"

#if PLUMB_HAVE_VIEWER
#include "viewer/file_view.h"
#include "viewer/page_assets.h"
#include "viewer/run_viewer.h"
#include "viewer/serve_address.h"
#include "viewer/viewer_channels.h"
#endif

namespace plumb::tools {
namespace {

void printViewUsage() {
  std::printf(
      "usage: plumb view --out TRAJ [--gt GT] [--map M.map] [--stats S.json] --serve PORT|HOST:PORT\n"
      "  Serves a finished run until Ctrl-C: open http://HOST:PORT/ in a browser, or connect\n"
      "  Foxglove/Lichtblick to ws://HOST:PORT (docs/VIEWER.md). PORT alone: this machine only;\n"
      "  HOST:PORT binds HOST and anyone who reaches it can watch.\n"
      "  --out FILE    the run's trajectory (TUM format, `plumb run --out`)\n"
      "  --gt FILE     ground truth: the estimate is aligned to it and coloured by its error\n"
      "  --map FILE    the run's map (`plumb run --save-map`): keyframes, loop edges, points, lines\n"
      "  --stats FILE  the run's statistics (`plumb run --stats`) on the status panel\n"
      "  --serve ADDR  where to serve (required)\n");
}

int fail(const std::string& message, int code = kExitFailed) {
  std::fprintf(stderr, "plumb view: %s\n", message.c_str());
  return code;
}

#if PLUMB_HAVE_VIEWER

std::atomic<bool> g_view_stop{false};
void onViewStop(int) { g_view_stop.store(true); }

Status readText(const std::string& path, std::string* out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return Status::Error(path + ": read failed");
  *out = text.str();
  return Status::Ok();
}

int runView(int argc, char** argv) {
  Args args(argc, argv, {"out", "gt", "map", "stats", "serve"}, {});
  if (args.help()) {
    printViewUsage();
    return kExitOk;
  }
  if (!args.error().empty() || !args.positional().empty() || !args.has("out") || !args.has("serve")) {
    std::fprintf(stderr, "plumb view: %s\n",
                 !args.error().empty() ? args.error().c_str()
                 : !args.positional().empty() ? ("unexpected argument " + args.positional()[0]).c_str()
                                              : "--out and --serve are required");
    printViewUsage();
    return kExitUsage;
  }
  viewer::ServeAddress address;
  Status st = viewer::parseServeAddress(args.get("serve"), &address);
  if (!st.ok()) return fail(st.message(), kExitUsage);

  viewer::FileViewInput input;
  input.title = args.get("out");
  TrajectoryReadOptions read_options;
  read_options.keep_lost_markers = true;  // `# <t> lost` / `dropped` lines break the drawn strips
  st = readTumTrajectory(args.get("out"), &input.estimate, read_options).withContext("--out");
  if (!st.ok()) return fail(st.message());
  if (args.has("gt")) {
    st = readTumTrajectory(args.get("gt"), &input.ground_truth).withContext("--gt");
    if (!st.ok()) return fail(st.message());
  }
  loop::SavedMap map;
  if (args.has("map")) {
    st = loadMapFile(args.get("map"), &map);
    if (!st.ok()) return fail(st.message());
    input.map = &map;
  }
  if (args.has("stats")) {
    st = readText(args.get("stats"), &input.stats_json);
    if (!st.ok()) return fail("--stats: " + st.message());
  }
  viewer::FileView view;
  viewer::FileViewSummary summary;
  st = view.build(input, &summary);
  if (!st.ok()) return fail(st.message());

  viewer::FoxgloveServerOptions options;
  options.host = address.host;
  options.port = address.port;
  options.name = "plumb view";
  viewer::FoxgloveServer server(options, viewer::viewerChannels(), viewer::pageAssets());
  std::signal(SIGINT, onViewStop);
  std::signal(SIGTERM, onViewStop);
  st = server.start([&view, &server] { view.tick(server); });
  if (!st.ok()) return fail(st.message());
  std::printf("trajectory: %zu poses%s", summary.estimate_poses,
              summary.ground_truth_poses > 0 ? "" : "\n");
  if (summary.ground_truth_poses > 0) {
    std::printf(", ground truth %zu poses, ATE RMSE %.4f m (max error %.4f m)\n", summary.ground_truth_poses,
                summary.ate_rmse_m, summary.error_max_m);
  }
  if (input.map != nullptr) {
    std::printf("map: %zu keyframes, %zu points, %zu line segments, %zu loop edges\n", summary.map_keyframes,
                summary.map_points, summary.map_lines, summary.loop_edges);
  }
  std::printf("serving %s (Foxglove/Lichtblick: ws://%s:%d)%s until Ctrl-C\n",
              viewer::serveUrl(address.host, server.boundPort()).c_str(), address.host.c_str(), server.boundPort(),
              address.loopback_only ? "" : "; anyone who can reach this address can watch");
  std::fflush(stdout);
  while (!g_view_stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  server.stop(1.0);
  const viewer::FoxgloveServerStats s = server.stats();
  std::printf("viewer: clients %llu, messages sent %llu, dropped for slow clients %llu\n",
              (unsigned long long)s.clients_accepted, (unsigned long long)s.messages_sent,
              (unsigned long long)s.messages_dropped);
  return kExitOk;
}

#else

int runView(int argc, char** argv) {
  Args args(argc, argv, {"out", "gt", "map", "stats", "serve"}, {});
  if (args.help()) {
    printViewUsage();
    return kExitOk;
  }
  return fail("this plumb was built without the viewer (install libwebsocketpp-dev libasio-dev and rebuild with "
              "-DPLUMB_VIEWER=ON, docs/VIEWER.md)");
}

#endif

}  // namespace
}  // namespace plumb::tools

PLUMB_COMMAND(view, "serve a finished run (trajectory, ground truth, map) to Foxglove and a browser",
              plumb::tools::runView);

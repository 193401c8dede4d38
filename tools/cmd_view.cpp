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
#include "tools/flags.h"
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

struct ViewOptions {
  std::string out, gt, map, stats, serve;
};

FlagTable viewFlagTable(ViewOptions* o) {
  FlagTable t;
  t.text("out", "FILE", &o->out, "the run's trajectory (TUM format, `plumb run --out`); required")
      .text("gt", "FILE", &o->gt, "ground truth: the estimate is aligned to it and coloured by its error")
      .text("map", "FILE", &o->map, "the run's map (`plumb run --save-map`): keyframes, loop edges, points, lines")
      .text("stats", "FILE", &o->stats, "the run's statistics (`plumb run --stats`) on the status panel")
      .text("serve", "PORT|HOST:PORT", &o->serve,
            "where to serve; required. PORT alone: this machine only; HOST:PORT binds\n"
            "HOST and anyone who reaches it can watch");
  return t;
}

void printViewUsage(const FlagTable& table) {
  std::printf(
      "usage: plumb view --out TRAJ [--gt GT] [--map M.map] [--stats S.json] --serve PORT|HOST:PORT\n"
      "Serves a finished run until Ctrl-C: open http://HOST:PORT/ in a browser, or connect\n"
      "Foxglove/Lichtblick to ws://HOST:PORT (docs/VIEWER.md).\n%s",
      table.usage().c_str());
}

// The command line; a usage error (exit 2) as a Status. *help: --help was given.
Status parseView(int argc, char** argv, FlagTable* table, const ViewOptions& o, bool* help) {
  PLUMB_RETURN_IF_ERROR(table->parse(argc, argv));
  *help = table->help();
  if (*help) return Status::Ok();
  if (!table->positional().empty()) return Status::Error("unexpected argument " + table->positional()[0]);
  if (o.out.empty() || o.serve.empty()) return Status::Error("--out and --serve are required");
  return Status::Ok();
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
  ViewOptions o;
  FlagTable table = viewFlagTable(&o);
  bool help = false;
  Status st = parseView(argc, argv, &table, o, &help);
  if (help) {
    printViewUsage(table);
    return kExitOk;
  }
  if (!st.ok()) return fail(st.message() + " (see plumb view --help)", kExitUsage);
  viewer::ServeAddress address;
  st = viewer::parseServeAddress(o.serve, &address);
  if (!st.ok()) return fail(st.message(), kExitUsage);

  viewer::FileViewInput input;
  input.title = o.out;
  TrajectoryReadOptions read_options;
  read_options.keep_lost_markers = true;  // `# <t> lost` / `dropped` lines break the drawn strips
  st = readTumTrajectory(o.out, &input.estimate, read_options).withContext("--out");
  if (!st.ok()) return fail(st.message());
  if (!o.gt.empty()) {
    st = readTumTrajectory(o.gt, &input.ground_truth).withContext("--gt");
    if (!st.ok()) return fail(st.message());
  }
  loop::SavedMap map;
  if (!o.map.empty()) {
    st = loadMapFile(o.map, &map);
    if (!st.ok()) return fail(st.message());
    input.map = &map;
  }
  if (!o.stats.empty()) {
    st = readText(o.stats, &input.stats_json);
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
  ViewOptions o;
  FlagTable table = viewFlagTable(&o);
  bool help = false;
  const Status st = parseView(argc, argv, &table, o, &help);
  if (help) {
    printViewUsage(table);
    return kExitOk;
  }
  if (!st.ok()) return fail(st.message() + " (see plumb view --help)", kExitUsage);
  return fail("this plumb was built without the viewer (install libwebsocketpp-dev libasio-dev and rebuild with "
              "-DPLUMB_VIEWER=ON, docs/VIEWER.md)");
}

#endif

}  // namespace
}  // namespace plumb::tools

PLUMB_COMMAND(view, "serve a finished run (trajectory, ground truth, map) to Foxglove and a browser",
              plumb::tools::runView);

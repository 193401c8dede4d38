#pragma once
// RunViewer: everything `plumb run --serve` adds, in one object (docs/VIEWER.md):
//   RunFeed (preallocated hand-off) <- ViewerSink (decorator around the run's sink)
//   FoxgloveServer (own thread) -> LiveView::tick drains the feed and publishes.
// The run calls runOdometry with wrap(outputs) instead of its outputs; nothing else changes.
#include <memory>
#include <string>

#include "pipeline/run/odometry_run.h"
#include "platform/status.h"
#include "viewer/foxglove_server.h"
#include "viewer/live_view.h"
#include "viewer/run_feed.h"
#include "viewer/serve_address.h"
#include "viewer/viewer_sink.h"

namespace plumb::viewer {

class RunViewer {
 public:
  // Binds `address` and starts serving (clients may connect before the run starts).
  static Status start(const ServeAddress& address, LiveViewOptions options, std::unique_ptr<RunViewer>* out);
  ~RunViewer();

  // The sink to run with: the viewer's decorator around `inner` (the run's outputs, which must
  // outlive the run). Once per run.
  OdometrySink& wrap(OdometrySink& inner);
  int port() const { return server_->boundPort(); }
  // After the run: the final state is published, clients get up to flush_seconds to receive it,
  // then they are closed and the thread joins.
  void stop(double flush_seconds = 2.0);
  // One line: clients, messages sent and dropped, the viewer thread's own allocations.
  std::string summary() const;

 private:
  RunViewer() = default;
  std::unique_ptr<RunFeed> feed_;
  std::unique_ptr<ViewerSink> sink_;
  std::unique_ptr<FoxgloveServer> server_;
  std::unique_ptr<LiveView> view_;
  uint64_t excluded_allocations_at_start_ = 0;
  uint64_t excluded_allocations_at_stop_ = 0;
  bool stopped_ = false;
};

// The address clients use, for messages: http://HOST:PORT/ (IPv6 in brackets).
std::string serveUrl(const std::string& host, int port);

}  // namespace plumb::viewer

#include "viewer/run_viewer.h"

#include <cinttypes>
#include <cstdio>

#include "platform/allocation_counter.h"
#include "viewer/page_assets.h"
#include "viewer/viewer_channels.h"

namespace plumb::viewer {
namespace {
// The map thread copies an image at most this often (the cost is the same whether or not anyone
// watches, so a client never changes what the run's threads do).
constexpr int64_t kImageIntervalNs = 100'000'000;
}  // namespace

Status RunViewer::start(const ServeAddress& address, LiveViewOptions options, std::unique_ptr<RunViewer>* out) {
  std::unique_ptr<RunViewer> v(new RunViewer());
  v->feed_ = std::make_unique<RunFeed>();
  v->feed_->setImageIntervalNs(kImageIntervalNs);
  FoxgloveServerOptions server_options;
  server_options.host = address.host;
  server_options.port = address.port;
  server_options.name = "plumb run";
  v->server_ = std::make_unique<FoxgloveServer>(server_options, viewerChannels(), pageAssets());
  v->view_ = std::make_unique<LiveView>(*v->feed_, *v->server_, std::move(options));
  LiveView* view = v->view_.get();
  v->excluded_allocations_at_start_ = excludedAllocationCount();
  PLUMB_RETURN_IF_ERROR(v->server_->start([view] { view->tick(); }));
  *out = std::move(v);
  return Status::Ok();
}

RunViewer::~RunViewer() { stop(0); }

OdometrySink& RunViewer::wrap(OdometrySink& inner) {
  sink_ = std::make_unique<ViewerSink>(inner, *feed_);
  return *sink_;
}

void RunViewer::stop(double flush_seconds) {
  if (stopped_) return;
  stopped_ = true;
  view_->markEnded();
  server_->stop(flush_seconds);
  excluded_allocations_at_stop_ = excludedAllocationCount();
}

std::string RunViewer::summary() const {
  const FoxgloveServerStats s = server_->stats();
  char line[512];
  std::snprintf(line, sizeof(line),
                "viewer: clients %" PRIu64 " (peak %" PRIu64 " at once, %" PRIu64 " closed for malformed messages, %" PRIu64
                " for not answering), messages sent %" PRIu64 ", dropped for slow clients %" PRIu64
                ", feed records dropped %" PRIu64 "; viewer thread allocations %" PRIu64 " (not on the frame path)",
                s.clients_accepted, s.peak_clients, s.clients_closed_malformed, s.clients_timed_out, s.messages_sent,
                s.messages_dropped, feed_->recordsDropped(),
                excluded_allocations_at_stop_ - excluded_allocations_at_start_);
  return line;
}

std::string serveUrl(const std::string& host, int port) {
  const bool v6 = host.find(':') != std::string::npos;
  return "http://" + (v6 ? "[" + host + "]" : host) + ":" + std::to_string(port) + "/";
}

}  // namespace plumb::viewer

#include "tools/serve_flag.h"

#include <cstdio>

#if PLUMB_HAVE_VIEWER
#include "viewer/run_viewer.h"
#endif

namespace plumb::tools {

#if PLUMB_HAVE_VIEWER

struct RunServe::Impl {
  std::unique_ptr<viewer::RunViewer> viewer;
};

Status checkServeSpec(const std::string& spec) {
  viewer::ServeAddress address;
  return spec.empty() ? Status::Ok() : viewer::parseServeAddress(spec, &address);
}

Status RunServe::start(const std::string& spec, const std::string& mode, const std::string& source) {
  if (spec.empty()) return Status::Ok();
  viewer::ServeAddress address;
  PLUMB_RETURN_IF_ERROR(viewer::parseServeAddress(spec, &address));
  viewer::LiveViewOptions options;
  options.mode = mode;
  options.source = source;
  PLUMB_RETURN_IF_ERROR(viewer::RunViewer::start(address, options, &impl_->viewer));
  std::fprintf(stderr, "plumb run: viewer at %s (Foxglove/Lichtblick: ws://%s:%d)%s\n",
               viewer::serveUrl(address.host, impl_->viewer->port()).c_str(),
               address.host.find(':') != std::string::npos ? ("[" + address.host + "]").c_str() : address.host.c_str(),
               impl_->viewer->port(),
               address.loopback_only ? "" : "; anyone who can reach this address can watch the run");
  return Status::Ok();
}

OdometrySink* RunServe::wrap(OdometrySink& outputs) {
  return impl_->viewer ? &impl_->viewer->wrap(outputs) : nullptr;
}

void RunServe::stop() {
  if (!impl_->viewer) return;
  impl_->viewer->stop();
  std::printf("%s\n", impl_->viewer->summary().c_str());
}

#else

struct RunServe::Impl {};

Status checkServeSpec(const std::string& spec) {
  if (spec.empty()) return Status::Ok();
  return Status::Error(
      "--serve: this plumb was built without the viewer (install libwebsocketpp-dev libasio-dev and rebuild with "
      "-DPLUMB_VIEWER=ON, docs/VIEWER.md)");
}

Status RunServe::start(const std::string& spec, const std::string&, const std::string&) { return checkServeSpec(spec); }

OdometrySink* RunServe::wrap(OdometrySink&) { return nullptr; }
void RunServe::stop() {}

#endif

RunServe::RunServe() : impl_(std::make_unique<Impl>()) {}
RunServe::~RunServe() = default;

}  // namespace plumb::tools

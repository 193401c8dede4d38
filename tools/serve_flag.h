#pragma once
// `plumb run --serve PORT|HOST:PORT` (docs/VIEWER.md): starts the viewer (viewer/run_viewer.h)
// before the run and stops it after, printing what it did. Kept apart from cmd_run.cpp so the run
// command only asks for sink() and calls stop(). Without the viewer in this build (PLUMB_VIEWER
// off) start() refuses a --serve with how to get it.
#include <memory>
#include <string>

#include "pipeline/run/odometry_run.h"
#include "platform/status.h"

namespace plumb::tools {

class RunServe {
 public:
  RunServe();
  ~RunServe();
  // spec '' = off (nothing happens). `outputs` must outlive this object.
  Status start(const std::string& spec, OdometrySink& outputs, const std::string& mode, const std::string& source);
  OdometrySink* sink();  // the decorator to run with, nullptr when off
  void stop();           // the final state reaches the clients, then the server ends

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace plumb::tools

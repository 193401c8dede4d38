#pragma once
// `plumb run --serve PORT|HOST:PORT` (docs/VIEWER.md), in the run command's steps
// (tools/run_command.h): the plan checks the address and starts the server (a port in use fails
// the run before any frame); the run wraps the outputs in the viewer's decorator and stops the
// server after, printing what it did. Without the viewer in this build (PLUMB_VIEWER off) start()
// refuses a --serve with how to get it.
#include <memory>
#include <string>

#include "pipeline/run/odometry_run.h"
#include "platform/status.h"

namespace plumb::tools {

// A usage error for a malformed spec ('' = off is fine), or when this build has no viewer.
Status checkServeSpec(const std::string& spec);

class RunServe {
 public:
  RunServe();
  ~RunServe();
  RunServe(const RunServe&) = delete;
  RunServe& operator=(const RunServe&) = delete;

  // Plan, after checkServeSpec: spec '' = off (nothing happens); else binds and serves.
  Status start(const std::string& spec, const std::string& mode, const std::string& source);
  // Run: the sink to run with, a decorator around `outputs` (which must outlive the run); nullptr
  // when off.
  OdometrySink* wrap(OdometrySink& outputs);
  // After the run: the final state reaches the clients, the server ends, its summary is printed.
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace plumb::tools

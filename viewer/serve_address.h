#pragma once
// The address `--serve` names (docs/VIEWER.md): PORT alone binds loopback only (127.0.0.1: only
// this machine can watch); HOST:PORT binds what the user names (0.0.0.0: anyone on the robot's
// networks can watch; [::1]:PORT for IPv6). PORT 0 takes any free port (the server prints it).
#include <string>

#include "platform/status.h"

namespace plumb::viewer {

struct ServeAddress {
  std::string host = "127.0.0.1";
  int port = 0;
  bool loopback_only = true;  // the host is 127.0.0.0/8 or ::1
};

Status parseServeAddress(const std::string& text, ServeAddress* out);

}  // namespace plumb::viewer

#include "viewer/serve_address.h"

#include <cstdlib>

namespace plumb::viewer {
namespace {

bool parsePort(const std::string& text, int* port) {
  if (text.empty() || text.size() > 5) return false;
  for (char c : text) {
    if (c < '0' || c > '9') return false;
  }
  *port = std::atoi(text.c_str());
  return *port <= 65535;
}

}  // namespace

Status parseServeAddress(const std::string& text, ServeAddress* out) {
  const std::string usage = "--serve takes PORT (loopback only) or HOST:PORT, e.g. 8765, 0.0.0.0:8765, [::1]:8765; got '" +
                            text + "'";
  ServeAddress a;
  std::string port;
  if (!text.empty() && text[0] == '[') {
    const std::size_t close = text.find(']');
    if (close == std::string::npos || close + 1 >= text.size() || text[close + 1] != ':') return Status::Error(usage);
    a.host = text.substr(1, close - 1);
    port = text.substr(close + 2);
  } else {
    const std::size_t colon = text.rfind(':');
    if (colon == std::string::npos) {
      port = text;
    } else {
      a.host = text.substr(0, colon);
      port = text.substr(colon + 1);
      if (a.host.empty() || a.host.find(':') != std::string::npos) return Status::Error(usage);
    }
  }
  if (!parsePort(port, &a.port)) return Status::Error(usage);
  if (a.host == "localhost") a.host = "127.0.0.1";
  a.loopback_only = a.host == "::1" || a.host.rfind("127.", 0) == 0;
  *out = a;
  return Status::Ok();
}

}  // namespace plumb::viewer

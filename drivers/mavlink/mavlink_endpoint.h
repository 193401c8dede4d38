#pragma once
// Where MAVLink frames go, parsed from a command-line spec:
//   udp:HOST:PORT          e.g. udp:127.0.0.1:14540 (IPv4 address or a host name)
//   serial:DEVICE:BAUD     e.g. serial:/dev/ttyUSB0:921600 (8N1 raw, no flow control)
#include <cstdint>
#include <string>

#include "platform/status.h"

namespace plumb {

struct MavlinkEndpoint {
  enum class Kind { kUdp, kSerial };
  Kind kind = Kind::kUdp;
  std::string host;    // udp
  uint16_t port = 0;   // udp
  std::string device;  // serial
  int baud = 0;        // serial
};

// Fills *out or returns an error that quotes the spec and shows the expected forms.
Status parseMavlinkEndpoint(const std::string& spec, MavlinkEndpoint* out);

// True for the serial speeds Linux termios can set (9600 .. 4000000).
bool isSupportedSerialBaud(int baud);

}  // namespace plumb

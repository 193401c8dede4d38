#include "drivers/mavlink/mavlink_endpoint.h"

#include <cerrno>
#include <cstdlib>

namespace plumb {
namespace {

constexpr int kSupportedBauds[] = {9600,    19200,   38400,   57600,   115200,  230400,
                                   460800,  500000,  576000,  921600,  1000000, 1152000,
                                   1500000, 2000000, 2500000, 3000000, 3500000, 4000000};

Status endpointError(const std::string& spec, const std::string& what) {
  return Status::Error("mavlink endpoint '" + spec + "': " + what +
                       " (expected udp:HOST:PORT or serial:DEVICE:BAUD, e.g. "
                       "udp:127.0.0.1:14540 or serial:/dev/ttyUSB0:921600)");
}

// Parses a decimal integer that must fill the whole text.
bool parseInteger(const std::string& text, long min, long max, long* value) {
  if (text.empty() || text.size() > 9) return false;
  for (char c : text) {
    if (c < '0' || c > '9') return false;
  }
  errno = 0;
  const long v = std::strtol(text.c_str(), nullptr, 10);
  if (errno != 0 || v < min || v > max) return false;
  *value = v;
  return true;
}

}  // namespace

bool isSupportedSerialBaud(int baud) {
  for (int b : kSupportedBauds) {
    if (b == baud) return true;
  }
  return false;
}

Status parseMavlinkEndpoint(const std::string& spec, MavlinkEndpoint* out) {
  const std::size_t colon = spec.find(':');
  if (colon == std::string::npos) return endpointError(spec, "no transport prefix");
  const std::string kind = spec.substr(0, colon);
  const std::string rest = spec.substr(colon + 1);
  // The last ':' separates the number, so device paths and host names may not contain one.
  const std::size_t last = rest.rfind(':');
  if (kind == "udp") {
    if (last == std::string::npos) return endpointError(spec, "missing :PORT");
    const std::string host = rest.substr(0, last);
    if (host.empty()) return endpointError(spec, "empty host");
    if (host.find(':') != std::string::npos) {
      // HOST:PORT:more is a spec with extra fields, not an IPv6 address: say which.
      const std::size_t first = rest.find(':');
      const std::size_t second = rest.find(':', first + 1);
      long port_value = 0;
      if (parseInteger(rest.substr(first + 1, second - first - 1), 1, 65535, &port_value)) {
        return endpointError(spec, "unexpected field '" + rest.substr(second + 1) + "' after udp:HOST:PORT");
      }
      return endpointError(spec, "IPv6 addresses are not supported, use an IPv4 address");
    }
    long port = 0;
    if (!parseInteger(rest.substr(last + 1), 1, 65535, &port)) {
      return endpointError(spec, "port must be a number in 1..65535");
    }
    out->kind = MavlinkEndpoint::Kind::kUdp;
    out->host = host;
    out->port = static_cast<uint16_t>(port);
    return Status::Ok();
  }
  if (kind == "serial") {
    if (last == std::string::npos) return endpointError(spec, "missing :BAUD");
    const std::string device = rest.substr(0, last);
    if (device.empty()) return endpointError(spec, "empty device path");
    long baud = 0;
    if (!parseInteger(rest.substr(last + 1), 1, 100000000, &baud) ||
        !isSupportedSerialBaud(static_cast<int>(baud))) {
      return endpointError(
          spec, "unsupported baud rate '" + rest.substr(last + 1) + "' (use e.g. 57600, 115200, 921600)");
    }
    out->kind = MavlinkEndpoint::Kind::kSerial;
    out->device = device;
    out->baud = static_cast<int>(baud);
    return Status::Ok();
  }
  return endpointError(spec, "unknown transport '" + kind + "'");
}

}  // namespace plumb

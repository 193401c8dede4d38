#include "drivers/mavlink/mavlink_transport.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

namespace plumb {
namespace {

speed_t termiosSpeed(int baud) {
  switch (baud) {
    case 9600:
      return B9600;
    case 19200:
      return B19200;
    case 38400:
      return B38400;
    case 57600:
      return B57600;
    case 115200:
      return B115200;
    case 230400:
      return B230400;
    case 460800:
      return B460800;
    case 500000:
      return B500000;
    case 576000:
      return B576000;
    case 921600:
      return B921600;
    case 1000000:
      return B1000000;
    case 1152000:
      return B1152000;
    case 1500000:
      return B1500000;
    case 2000000:
      return B2000000;
    case 2500000:
      return B2500000;
    case 3000000:
      return B3000000;
    case 3500000:
      return B3500000;
    case 4000000:
      return B4000000;
    default:
      return B0;
  }
}

std::string errnoText(int err) { return std::strerror(err); }

}  // namespace

MavlinkTransport::~MavlinkTransport() { close(); }

void MavlinkTransport::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  pending_size_ = 0;
}

Status MavlinkTransport::open(const MavlinkEndpoint& endpoint) {
  close();
  if (endpoint.kind == MavlinkEndpoint::Kind::kUdp) {
    addrinfo hints{};
    hints.ai_family = AF_INET;
    hints.ai_socktype = SOCK_DGRAM;
    addrinfo* found = nullptr;
    const int rc = ::getaddrinfo(endpoint.host.c_str(), nullptr, &hints, &found);
    if (rc != 0 || found == nullptr) {
      return Status::Error("mavlink udp: cannot resolve host '" + endpoint.host + "': " + ::gai_strerror(rc));
    }
    std::memcpy(&destination_, found->ai_addr, sizeof(destination_));
    ::freeaddrinfo(found);
    destination_.sin_port = htons(endpoint.port);
    fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd_ < 0) return Status::Error("mavlink udp: socket(): " + errnoText(errno));
    // Allows udp:x.x.x.255 (a common way to reach a ground station on a radio LAN).
    const int one = 1;
    ::setsockopt(fd_, SOL_SOCKET, SO_BROADCAST, &one, sizeof(one));
    is_udp_ = true;
    return Status::Ok();
  }

  const std::string& path = endpoint.device;
  fd_ = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) return Status::Error("mavlink serial: cannot open '" + path + "': " + errnoText(errno));
  termios tio{};
  if (::tcgetattr(fd_, &tio) != 0) {
    const int err = errno;
    close();
    return Status::Error("mavlink serial: '" + path + "' is not a serial port: " + errnoText(err));
  }
  ::cfmakeraw(&tio);
  tio.c_cflag |= CLOCAL | CREAD;
  tio.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | CRTSCTS);
  const speed_t speed = termiosSpeed(endpoint.baud);
  if (speed == B0 || ::cfsetispeed(&tio, speed) != 0 || ::cfsetospeed(&tio, speed) != 0 ||
      ::tcsetattr(fd_, TCSANOW, &tio) != 0) {
    const int err = errno;
    close();
    return Status::Error("mavlink serial: cannot set '" + path + "' to " + std::to_string(endpoint.baud) +
                         " baud raw: " + errnoText(err));
  }
  is_udp_ = false;
  return Status::Ok();
}

bool MavlinkTransport::flushPending() {
  while (pending_size_ > 0) {
    const ssize_t n = ::write(fd_, pending_, pending_size_);
    if (n < 0) {
      if (errno == EINTR) continue;
      last_errno_ = errno;
      return false;
    }
    std::memmove(pending_, pending_ + n, pending_size_ - static_cast<std::size_t>(n));
    pending_size_ -= static_cast<std::size_t>(n);
    if (n == 0) return false;
  }
  return true;
}

bool MavlinkTransport::trySend(const uint8_t* frame, std::size_t size) {
  if (fd_ < 0 || size > sizeof(pending_)) return false;
  if (is_udp_) {
    for (;;) {
      const ssize_t n = ::sendto(fd_, frame, size, MSG_DONTWAIT | MSG_NOSIGNAL,
                                 reinterpret_cast<const sockaddr*>(&destination_), sizeof(destination_));
      if (n == static_cast<ssize_t>(size)) return true;
      if (n < 0 && errno == EINTR) continue;
      last_errno_ = n < 0 ? errno : EMSGSIZE;
      return false;
    }
  }
  if (!flushPending()) return false;
  std::size_t written = 0;
  while (written < size) {
    const ssize_t n = ::write(fd_, frame + written, size - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n < 0) last_errno_ = errno;
      break;
    }
    written += static_cast<std::size_t>(n);
  }
  if (written == 0) return false;  // nothing left the process: the frame is dropped whole
  if (written < size) {            // keep the tail so the stream stays frame-aligned
    pending_size_ = size - written;
    std::memcpy(pending_, frame + written, pending_size_);
  }
  return true;
}

}  // namespace plumb

#pragma once
// Byte transport for MAVLink frames that never blocks the caller: a non-blocking UDP socket or a
// raw non-blocking serial port. A frame that cannot be handed to the kernel at once is dropped
// and the caller counts it. No heap allocation after open().
//
// Serial ports accept partial writes; a torn frame would corrupt the stream, so the unwritten
// tail of a frame is kept (one frame of fixed storage) and flushed before anything new. While a
// tail is pending, new frames are dropped whole.
#include <netinet/in.h>

#include <cstddef>
#include <cstdint>

#include "drivers/mavlink/mavlink_endpoint.h"
#include "drivers/mavlink/mavlink_frame.h"
#include "platform/status.h"

namespace plumb {

class MavlinkTransport {
 public:
  MavlinkTransport() = default;
  ~MavlinkTransport();
  MavlinkTransport(const MavlinkTransport&) = delete;
  MavlinkTransport& operator=(const MavlinkTransport&) = delete;

  // Opens the socket or the serial port (resolves the host, sets termios). May allocate.
  Status open(const MavlinkEndpoint& endpoint);
  void close();
  bool isOpen() const { return fd_ >= 0; }

  // Hands one whole frame to the kernel, or returns false (dropped) when it would block or fails.
  bool trySend(const uint8_t* frame, std::size_t size);

  int lastErrno() const { return last_errno_; }

 private:
  bool flushPending();

  int fd_ = -1;
  bool is_udp_ = false;
  sockaddr_in destination_{};
  uint8_t pending_[kMavlinkV2MaxFrameBytes] = {};
  std::size_t pending_size_ = 0;
  int last_errno_ = 0;
};

}  // namespace plumb

// plumb_vmcam_usbip: connects a gadget bound to usbip-vudc (the USB/IP virtual device controller)
// to vhci-hcd (the USB/IP virtual host controller) inside one machine, over a loopback TCP
// connection, without the usbip tools: the kernel halves take the two ends of the connection as
// file descriptors through sysfs. For the virtual-machine camera bench (scripts/vm_camera_guest.sh),
// whose UVC gadget cannot bind to dummy_hcd (it has no isochronous endpoints).
//   plumb_vmcam_usbip [--vudc usbip-vudc.0] [--port 0] [--speed 3 (high)]
// Exit 0 attached, 1 a step failed (message on stderr).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace {

bool writeSysfs(const std::string& path, const std::string& text) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) {
    std::fprintf(stderr, "usbip: cannot open %s: %s\n", path.c_str(), std::strerror(errno));
    return false;
  }
  const bool ok = std::fputs(text.c_str(), f) >= 0;
  const bool closed = std::fclose(f) == 0;
  if (!ok || !closed) std::fprintf(stderr, "usbip: writing '%s' to %s: %s\n", text.c_str(), path.c_str(), std::strerror(errno));
  return ok && closed;
}

}  // namespace

int main(int argc, char** argv) {
  std::string vudc = "usbip-vudc.0";
  int port = 0, speed = 3;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--vudc") == 0) vudc = argv[i + 1];
    else if (std::strcmp(argv[i], "--port") == 0) port = std::atoi(argv[i + 1]);
    else if (std::strcmp(argv[i], "--speed") == 0) speed = std::atoi(argv[i + 1]);
  }
  // A loopback TCP connection (127.0.0.1, an ephemeral port): the device side gets one end, the
  // host side the other.
  const int listener = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof address;
  if (listener < 0 || bind(listener, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
      listen(listener, 1) != 0 || getsockname(listener, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
    std::fprintf(stderr, "usbip: loopback listener: %s\n", std::strerror(errno));
    return 1;
  }
  const int host_end = socket(AF_INET, SOCK_STREAM, 0);
  if (host_end < 0 || connect(host_end, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    std::fprintf(stderr, "usbip: connect 127.0.0.1:%d: %s\n", ntohs(address.sin_port), std::strerror(errno));
    return 1;
  }
  const int device_end = accept(listener, nullptr, nullptr);
  if (device_end < 0) {
    std::fprintf(stderr, "usbip: accept: %s\n", std::strerror(errno));
    return 1;
  }
  if (!writeSysfs("/sys/devices/platform/" + vudc + "/usbip_sockfd", std::to_string(device_end))) return 1;
  // vhci's attach: "port sockfd devid speed"; the devid only labels the remote device.
  const std::string attach = std::to_string(port) + " " + std::to_string(host_end) + " " +
                             std::to_string((1 << 16) | 2) + " " + std::to_string(speed);
  if (!writeSysfs("/sys/devices/platform/vhci_hcd.0/attach", attach)) return 1;
  std::printf("usbip: %s attached to vhci_hcd port %d over 127.0.0.1:%d\n", vudc.c_str(), port, ntohs(address.sin_port));
  return 0;  // the kernel holds both sockets now
}

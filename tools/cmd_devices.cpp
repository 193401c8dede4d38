// plumb devices: which RGB-D cameras are connected (libusb VID:PID table), what OpenNI2 sees,
// which V4L2 nodes exist; --watch follows hot-plug events.
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>

#include "drivers/openni2/openni2_source.h"
#include "tools/args.h"
#include "tools/command.h"
#ifdef PLUMB_HAVE_LIBUSB
#include "drivers/usb/camera_monitor.h"
#include "drivers/usb/libusb_backend.h"
#endif

namespace {

#ifdef PLUMB_HAVE_LIBUSB  // only the hot-plug watch below stops on Ctrl-C
volatile std::sig_atomic_t g_stop_requested = 0;
void requestStop(int) { g_stop_requested = 1; }
#endif

void printHelp() {
  std::printf(
      "usage: plumb devices [--watch SECONDS]\n"
      "Lists connected RGB-D cameras (USB VID:PID table) with their bus path and the plumb\n"
      "source that can open each, the devices OpenNI2 enumerates, and the V4L2 video nodes.\n"
      "No camera connected is a normal answer (exit 0).\n\n"
      "  --watch S   then report cameras arriving and leaving (hot-plug) for S seconds\n");
}

void listV4l2Nodes() {
  std::error_code ec;
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator("/dev", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("video", 0) == 0) {
      std::printf("v4l2: %s (open with v4l2:%s --camera FILE)\n", entry.path().c_str(),
                  entry.path().c_str());
      ++count;
    }
  }
  if (count == 0) std::printf("v4l2: no /dev/video* nodes\n");
}

void listOpenNI2() {
  std::vector<plumb::OpenNI2DeviceInfo> devices;
  const plumb::Status st = plumb::listOpenNI2Devices(&devices);
  if (!st.ok()) {
    std::printf("openni2: %s\n", st.message().c_str());
    return;
  }
  if (devices.empty()) std::printf("openni2: no OpenNI2 device found\n");
  for (const auto& d : devices)
    std::printf("openni2: %s %s (%04x:%04x) uri %s\n", d.vendor.c_str(), d.name.c_str(),
                d.usb_vendor_id, d.usb_product_id, d.uri.c_str());
}

int runDevices(int argc, char** argv) {
  const plumb::tools::Args args(argc, argv, {"watch"}, {});
  if (args.help()) {
    printHelp();
    return 0;
  }
  bool ok = true;
  const double watch_s = args.getDouble("watch", 0, &ok);
  if (!args.error().empty() || !ok || watch_s < 0 || !args.positional().empty()) {
    std::fprintf(stderr, "plumb devices: bad arguments (see plumb devices --help)\n");
    return 2;
  }
#ifdef PLUMB_HAVE_LIBUSB
  std::unique_ptr<plumb::UsbBackend> backend;
  plumb::Status st = plumb::openLibusbBackend(&backend);
  if (!st.ok()) {
    std::printf("usb: %s\n", st.message().c_str());
  } else {
    plumb::CameraMonitor monitor(*backend);
    st = monitor.scan();
    if (!st.ok()) std::printf("usb: %s\n", st.message().c_str());
    else std::printf("usb: %s", plumb::describeCameras(monitor.cameras()).c_str());
    if (watch_s > 0) {
      st = monitor.start([](const plumb::CameraChange& change) {
        // The event's time on the steady clock (CLOCK_MONOTONIC), to measure replug delays.
        const double t_s = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
        std::printf("usb: %s %s at %.3f s\n", change.arrived ? "arrived" : "left",
                    plumb::describeCamera(change.camera).c_str(), t_s);
        std::fflush(stdout);
      });
      if (!st.ok()) {
        std::printf("usb: %s\n", st.message().c_str());
      } else {
        std::printf("usb: watching hot-plug for %.0f s (Ctrl-C stops)\n", watch_s);
        std::signal(SIGINT, requestStop);
        const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(watch_s);
        while (!g_stop_requested && std::chrono::steady_clock::now() < end) {
          if (!monitor.pollEvents(200).ok()) break;
        }
        std::signal(SIGINT, SIG_DFL);
      }
    }
  }
#else
  if (watch_s > 0) std::printf("usb: built without libusb-1.0: no hot-plug\n");
  std::printf("usb: built without libusb-1.0: cannot list USB cameras\n");
#endif
  listOpenNI2();
  listV4l2Nodes();
  return 0;
}

}  // namespace

PLUMB_COMMAND(devices, "list connected RGB-D cameras and which source opens them", runDevices);

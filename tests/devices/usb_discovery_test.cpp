// libusb discovery: the VID:PID table, hot-plug handling with injected events (fake backend),
// and a real enumeration of this machine's bus (which has no camera attached in CI).
#include <gtest/gtest.h>

#ifdef PLUMB_HAVE_LIBUSB
#include "drivers/usb/camera_monitor.h"
#include "drivers/usb/libusb_backend.h"
#include "drivers/usb/usb_arrival_waker.h"

namespace plumb {
namespace {

TEST(UsbCameraTable, KnownIdsMapToTheirSource) {
  const UsbCameraModel* d435 = lookupUsbCamera(0x8086, 0x0b07);
  ASSERT_NE(d435, nullptr);
  EXPECT_STREQ(d435->name, "Intel RealSense D435");
  EXPECT_EQ(d435->access, CameraAccess::kV4l2);
  const UsbCameraModel* xtion = lookupUsbCamera(0x1d27, 0x0601);
  ASSERT_NE(xtion, nullptr);
  EXPECT_EQ(xtion->access, CameraAccess::kOpenNI2);
  const UsbCameraModel* kinect = lookupUsbCamera(0x045e, 0x02ae);
  ASSERT_NE(kinect, nullptr);
  EXPECT_EQ(kinect->access, CameraAccess::kUnsupported);
  ASSERT_NE(lookupUsbCamera(0x2bc5, 0x0401), nullptr);  // any Orbbec product
  EXPECT_EQ(lookupUsbCamera(0x2bc5, 0x1234)->access, CameraAccess::kOpenNI2);
  EXPECT_EQ(lookupUsbCamera(0x8086, 0x1234), nullptr);  // some other Intel device
  EXPECT_EQ(lookupUsbCamera(0x045e, 0x02b0), nullptr);  // Kinect motor, not the camera
  EXPECT_EQ(lookupUsbCamera(0x1d6b, 0x0002), nullptr);  // Linux root hub
}

TEST(UsbCameraTable, EntriesAreWellFormedAndTheFirstMatchIsTheMostSpecific) {
  std::size_t count = 0;
  const UsbCameraModel* table = usbCameraTable(&count);
  ASSERT_GT(count, 10u);
  for (std::size_t i = 0; i < count; ++i) {
    EXPECT_LE(table[i].product_id_first, table[i].product_id_last) << table[i].name;
    // No entry may be shadowed by an earlier one (lookups return the first match).
    EXPECT_EQ(lookupUsbCamera(table[i].vendor_id, table[i].product_id_first), &table[i])
        << table[i].name;
  }
}

// Fake backend: the test sets the devices on the bus and fires hot-plug events by hand.
class FakeUsbBackend : public UsbBackend {
 public:
  std::vector<UsbDeviceId> bus;
  bool hotplug = true;
  UsbHotplugHandler* handler = nullptr;
  Status listDevices(std::vector<UsbDeviceId>* devices) override {
    *devices = bus;
    return Status::Ok();
  }
  bool supportsHotplug() const override { return hotplug; }
  Status startHotplug(UsbHotplugHandler* h) override {
    handler = h;
    return Status::Ok();
  }
  void stopHotplug() override { handler = nullptr; }
  Status pollEvents(int) override { return Status::Ok(); }
};

UsbDeviceId device(uint16_t vid, uint16_t pid, const std::string& port) {
  UsbDeviceId id;
  id.vendor_id = vid;
  id.product_id = pid;
  id.bus = static_cast<uint8_t>(port[0] - '0');
  id.port_path = port;
  return id;
}

TEST(UsbArrivalWaker, WithoutAConfiguredIdEveryTableCameraArrivalWakesAndNoDepartureCounts) {
  auto backend = std::make_unique<FakeUsbBackend>();
  FakeUsbBackend* fake = backend.get();
  int arrived = 0, left = 0;
  std::unique_ptr<UsbArrivalWaker> waker;
  ASSERT_TRUE(UsbArrivalWaker::create(std::move(backend), UsbCameraId{}, {[&] { ++arrived; }, [&] { ++left; }}, &waker)
                  .ok());
  ASSERT_NE(fake->handler, nullptr);
  fake->handler->onArrived(device(0x046d, 0xc52b, "1-3"));  // a mouse
  EXPECT_EQ(arrived, 0);
  fake->handler->onArrived(device(0x8086, 0x0b07, "2-1"));  // a D435
  EXPECT_EQ(arrived, 1);
  fake->handler->onLeft(device(0x8086, 0x0b07, "2-1"));  // whose camera? unknown: not a disconnect
  EXPECT_EQ(left, 0);
  fake->handler->onArrived(device(0x2bc5, 0x0401, "2-2"));  // an Orbbec
  EXPECT_EQ(arrived, 2);
  EXPECT_EQ(waker->arrivals(), 2u);
  EXPECT_EQ(waker->departures(), 0u);
  EXPECT_EQ(waker->describe(), "usb: RGB-D cameras arrived 2");
  EXPECT_TRUE(waker->pollOnce(0).ok());
}

TEST(UsbArrivalWaker, AConfiguredIdWakesOnItsArrivalAndReportsItsDeparture) {
  auto backend = std::make_unique<FakeUsbBackend>();
  FakeUsbBackend* fake = backend.get();
  int arrived = 0, left = 0;
  UsbCameraId gadget;
  ASSERT_TRUE(parseUsbCameraId("1d6b:104", &gadget));  // not in the table: configured ids need not be
  std::unique_ptr<UsbArrivalWaker> waker;
  ASSERT_TRUE(UsbArrivalWaker::create(std::move(backend), gadget, {[&] { ++arrived; }, [&] { ++left; }}, &waker).ok());
  fake->handler->onArrived(device(0x8086, 0x0b07, "2-1"));  // another camera: not ours
  fake->handler->onLeft(device(0x8086, 0x0b07, "2-1"));
  EXPECT_EQ(arrived + left, 0);
  fake->handler->onLeft(device(0x1d6b, 0x0104, "1-1"));
  EXPECT_EQ(left, 1);
  EXPECT_EQ(arrived, 0);
  fake->handler->onArrived(device(0x1d6b, 0x0104, "1-1"));
  EXPECT_EQ(arrived, 1);
  EXPECT_EQ(waker->describe(), "usb 1d6b:0104 arrived 1, left 1");
}

TEST(UsbArrivalWaker, NeedsHotplugAndAWellFormedId) {
  auto without_hotplug = std::make_unique<FakeUsbBackend>();
  without_hotplug->hotplug = false;
  std::unique_ptr<UsbArrivalWaker> none;
  EXPECT_FALSE(UsbArrivalWaker::create(std::move(without_hotplug), UsbCameraId{}, {}, &none).ok());
  EXPECT_EQ(none, nullptr);
  UsbCameraId id;
  EXPECT_TRUE(parseUsbCameraId("8086:0B07", &id));
  EXPECT_EQ(id.vendor_id, 0x8086);
  EXPECT_EQ(id.product_id, 0x0b07);
  for (const char* bad : {"", "8086", "8086:", ":0b07", "8086:0b07x", "18086:0b07", "0:0", "80 6:0b07", "-1:2", "g086:0b07"}) {
    UsbCameraId untouched{1, 2};
    EXPECT_FALSE(parseUsbCameraId(bad, &untouched)) << bad;
    EXPECT_EQ(untouched.vendor_id, 1) << bad;
  }
}

TEST(CameraMonitor, ScanKeepsOnlyCamerasAndSaysWhichSourceOpensThem) {
  FakeUsbBackend backend;
  backend.bus = {device(0x1d6b, 0x0003, "2"), device(0x8086, 0x0b3a, "2-1"),
                 device(0x046d, 0xc52b, "1-3"), device(0x1d27, 0x0600, "1-4.2")};
  CameraMonitor monitor(backend);
  ASSERT_TRUE(monitor.scan().ok());
  ASSERT_EQ(monitor.cameras().size(), 2u);
  EXPECT_EQ(describeCamera(monitor.cameras()[0]),
            "8086:0b3a Intel RealSense D435i at usb 2-1 -> v4l2 (uvcvideo: colour + Z16 nodes)");
  EXPECT_EQ(monitor.cameras()[1].usb.port_path, "1-4.2");
  EXPECT_EQ(monitor.cameras()[1].model->access, CameraAccess::kOpenNI2);
}

TEST(CameraMonitor, InjectedHotplugEventsAreReportedOnceEach) {
  FakeUsbBackend backend;
  backend.bus = {device(0x8086, 0x0b07, "2-1")};
  CameraMonitor monitor(backend);
  ASSERT_TRUE(monitor.scan().ok());
  std::vector<std::string> heard;
  ASSERT_TRUE(monitor
                  .start([&](const CameraChange& c) {
                    heard.push_back((c.arrived ? "+" : "-") + c.camera.usb.port_path);
                  })
                  .ok());
  ASSERT_NE(backend.handler, nullptr);
  backend.handler->onArrived(device(0x2bc5, 0x0401, "1-2"));  // Orbbec Astra plugged in
  backend.handler->onArrived(device(0x2bc5, 0x0401, "1-2"));  // duplicate event: ignored
  backend.handler->onArrived(device(0x046d, 0xc52b, "1-3"));  // a mouse: ignored
  backend.handler->onLeft(device(0x8086, 0x0b07, "2-1"));     // the D435 unplugged
  backend.handler->onLeft(device(0x8086, 0x0b07, "2-1"));     // again: ignored
  backend.handler->onLeft(device(0x046d, 0xc52b, "1-3"));     // mouse leaves: ignored
  backend.handler->onArrived(device(0x8086, 0x0b07, "2-2"));  // replugged into another port
  EXPECT_EQ(heard, (std::vector<std::string>{"+1-2", "-2-1", "+2-2"}));
  ASSERT_EQ(monitor.cameras().size(), 2u);
  EXPECT_EQ(monitor.cameras()[0].model->vendor_id, 0x2bc5);
  monitor.stop();
  EXPECT_EQ(backend.handler, nullptr);
}

TEST(CameraMonitor, NoHotplugSupportIsACleanMessage) {
  FakeUsbBackend backend;
  backend.hotplug = false;
  CameraMonitor monitor(backend);
  const Status st = monitor.start([](const CameraChange&) {});
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("not supported"), std::string::npos);
}

TEST(LibusbBackend, EnumeratingThisMachineSucceeds) {
  std::unique_ptr<UsbBackend> backend;
  const Status opened = openLibusbBackend(&backend);
  ASSERT_TRUE(opened.ok()) << opened.message();
  CameraMonitor monitor(*backend);
  const Status scanned = monitor.scan();
  ASSERT_TRUE(scanned.ok()) << scanned.message();
  const std::string report = describeCameras(monitor.cameras());
  std::printf("libusb (hot-plug %s): %s", backend->supportsHotplug() ? "supported" : "unsupported",
              report.c_str());
  if (monitor.cameras().empty()) {
    EXPECT_EQ(report.rfind("no RGB-D camera connected", 0), 0u) << report;
  }
  if (backend->supportsHotplug()) {
    ASSERT_TRUE(monitor.start([](const CameraChange&) {}).ok());
    EXPECT_TRUE(monitor.pollEvents(10).ok());
    monitor.stop();
  }
}

}  // namespace
}  // namespace plumb

#else
TEST(LibusbBackend, BuiltWithoutLibusb) { GTEST_SKIP() << "built without libusb-1.0"; }
#endif

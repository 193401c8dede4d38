// OpenNI2 without a camera: initialisation, enumeration (none found is a clean result), clear
// errors for a missing device or file, and the probe showing why we cannot write .oni files
// without hardware (openni::Recorder needs a started stream of a real device).
#include <gtest/gtest.h>

#include <fstream>

#include "drivers/openni2/openni2_source.h"
#include "tests/drivers/device_test_util.h"

#ifdef PLUMB_HAVE_OPENNI2
#include <OpenNI.h>
#endif

namespace plumb {
namespace {

#ifdef PLUMB_HAVE_OPENNI2

TEST(OpenNI2, InitialisesAndEnumerates) {
  const Status init = initializeOpenNI2();
  ASSERT_TRUE(init.ok()) << init.message();
  EXPECT_TRUE(initializeOpenNI2().ok());  // idempotent
  std::vector<OpenNI2DeviceInfo> devices;
  const Status listed = listOpenNI2Devices(&devices);
  ASSERT_TRUE(listed.ok()) << listed.message();
  std::printf("OpenNI2 devices: %zu\n", devices.size());
  if (!devices.empty()) GTEST_SKIP() << "a device is attached; the no-device checks do not apply";
  std::unique_ptr<FrameSource> source;
  const Status opened = openOpenNI2Source({}, nullptr, &source);
  ASSERT_FALSE(opened.ok());
  EXPECT_EQ(opened.message(), "openni2: no OpenNI2 device connected");
}

TEST(OpenNI2, MissingOrBogusOniFilesAreClearErrors) {
  OpenNI2SourceOptions options;
  options.uri = "/nonexistent/take1.oni";
  std::unique_ptr<FrameSource> source;
  Status st = openOpenNI2Source(options, nullptr, &source);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("/nonexistent/take1.oni"), std::string::npos) << st.message();

  test::ScratchDir dir("oni");
  options.uri = dir.file("bogus.oni");
  std::ofstream(options.uri) << "this is not an OpenNI recording";
  st = openOpenNI2Source(options, nullptr, &source);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("bogus.oni"), std::string::npos) << st.message();
}

TEST(OpenNI2, RecorderCannotWriteOniWithoutADeviceStream) {
  ASSERT_TRUE(initializeOpenNI2().ok());
  test::ScratchDir dir("onirec");
  openni::Recorder recorder;
  const openni::Status created = recorder.create(dir.file("x.oni").c_str());
  openni::VideoStream unattached;  // the only streams OpenNI2 makes come from an opened Device
  const openni::Status attached = recorder.attach(unattached);
  EXPECT_NE(attached, openni::STATUS_OK)
      << "if this ever succeeds, .oni writing without hardware became possible: revisit docs";
  std::printf("Recorder::create %s, attach(stream without device) %s: %s\n",
              created == openni::STATUS_OK ? "ok" : "failed",
              attached == openni::STATUS_OK ? "ok" : "failed", openni::OpenNI::getExtendedError());
  recorder.destroy();
}

#else
TEST(OpenNI2, BuiltWithoutOpenNI2IsAClearMessage) {
  std::vector<OpenNI2DeviceInfo> devices;
  EXPECT_EQ(listOpenNI2Devices(&devices).message(), "built without OpenNI2 (libopenni2-dev)");
}
#endif

}  // namespace
}  // namespace plumb

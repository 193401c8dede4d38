// V4L2 with a depth camera that is not registered to colour (docs/DATA_FORMATS.md "Unregistered
// depth"): the Z16 node is opened at the depth camera's size, not the colour camera's, and its
// images come through at that size for the pipeline's register stage. The fake driver answers
// S_FMT with its node's own size, so asking for the colour size would fail the open.
#include <gtest/gtest.h>

#include "drivers/v4l2/v4l2_source.h"
#include "tests/devices/fake_v4l2_device.h"

namespace plumb {
namespace {

TEST(V4l2UnregisteredDepth, DepthNodeOpensAtTheDepthCamerasSize) {
  PinholeCamera camera;  // colour 4x2
  camera.fx = camera.fy = 2;
  camera.cx = 2;
  camera.cy = 1;
  camera.width = 4;
  camera.height = 2;
  DepthCamera depth;  // depth 2x2, 1 cm beside it
  depth.fx = depth.fy = 1;
  depth.cx = depth.cy = 1;
  depth.width = depth.height = 2;
  depth.tx = 0.01;
  camera.depth_camera = depth;
  ASSERT_EQ(camera.validate(), "");

  test::FakeV4l2Device fake;
  test::FakeV4l2Node colour;  // YUYV 4x2
  colour.fill = [](uint64_t, uint8_t* data, std::size_t, uint32_t*) {
    for (int i = 0; i < 16; i += 2) {
      data[i] = 100;
      data[i + 1] = 128;
    }
  };
  test::FakeV4l2Node z16;  // Z16 2x2, every pixel 1500 + k
  z16.fourcc = V4L2_PIX_FMT_Z16;
  z16.width = 2;
  z16.height = 2;
  z16.bytes_per_line = 4;
  z16.fill = [](uint64_t k, uint8_t* data, std::size_t, uint32_t*) {
    const uint16_t v = static_cast<uint16_t>(1500 + k);
    for (int i = 0; i < 8; i += 2) {
      data[i] = v & 0xFF;
      data[i + 1] = v >> 8;
    }
  };
  fake.nodes["/dev/video0"] = colour;
  fake.nodes["/dev/video1"] = z16;
  V4l2SourceOptions options;
  options.depth_device = "/dev/video1";
  std::unique_ptr<V4l2Source> source;
  const Status st = V4l2Source::open(options, camera, fake, &source);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_FALSE(source->camera().depthRegistered());
  RgbdImage out;
  ASSERT_EQ(source->next(out), SourceResult::kFrame);
  EXPECT_EQ(out.bgr.size(), cv::Size(4, 2));
  ASSERT_EQ(out.depth_raw.size(), cv::Size(2, 2));
  EXPECT_EQ(out.depth_raw.at<uint16_t>(1, 1), 1500);

  // The same node under a camera that says depth is registered (4x2): the driver's 2x2 answer is
  // a substituted size, refused with a message rather than read wrongly.
  camera.depth_camera.reset();
  test::FakeV4l2Device fake2;
  fake2.nodes["/dev/video0"] = colour;
  fake2.nodes["/dev/video1"] = z16;
  const Status refused = V4l2Source::open(options, camera, fake2, &source);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("/dev/video1"), std::string::npos) << refused.message();
}

}  // namespace
}  // namespace plumb

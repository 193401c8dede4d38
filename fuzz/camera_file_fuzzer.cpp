// libFuzzer target for the camera file reader (drivers/dataset/camera_file.h). Beyond "no crash":
// an accepted camera passes PinholeCamera::validate(), and writeCameraFile() then
// readCameraFile() gives it back bit for bit (the writer's documented promise).
#include <cstdint>
#include <cstring>
#include <string>

#include "drivers/dataset/camera_file.h"
#include "fuzz/fuzz_support.h"

namespace {

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  plumb::fuzz::MemFile file(data, size);
  if (!file.ok()) return 0;
  plumb::PinholeCamera camera;
  if (!plumb::readCameraFile(file.path(), &camera).ok()) return 0;
  FUZZ_CHECK(camera.validate().empty());
  FUZZ_CHECK(camera.width > 0 && camera.height > 0);
  FUZZ_CHECK(camera.fx != 0 && camera.fy != 0);

  plumb::fuzz::MemFile written(std::string{});
  if (!written.ok()) return 0;
  FUZZ_CHECK(plumb::writeCameraFile(written.path(), camera).ok());
  plumb::PinholeCamera reread;
  FUZZ_CHECK(plumb::readCameraFile(written.path(), &reread).ok());
  const double plumb::PinholeCamera::*reals[] = {
      &plumb::PinholeCamera::fx, &plumb::PinholeCamera::fy, &plumb::PinholeCamera::cx,
      &plumb::PinholeCamera::cy, &plumb::PinholeCamera::k1, &plumb::PinholeCamera::k2,
      &plumb::PinholeCamera::p1, &plumb::PinholeCamera::p2, &plumb::PinholeCamera::k3,
      &plumb::PinholeCamera::depth_factor, &plumb::PinholeCamera::baseline_m,
      &plumb::PinholeCamera::rolling_shutter_readout_s};
  for (auto field : reals) FUZZ_CHECK(sameBits(reread.*field, camera.*field));
  FUZZ_CHECK(reread.width == camera.width && reread.height == camera.height);
  FUZZ_CHECK(reread.depth_camera.has_value() == camera.depth_camera.has_value());
  if (camera.depth_camera) {
    const plumb::DepthCamera& a = *camera.depth_camera;
    const plumb::DepthCamera& b = *reread.depth_camera;
    const double plumb::DepthCamera::*depth_reals[] = {
        &plumb::DepthCamera::fx, &plumb::DepthCamera::fy, &plumb::DepthCamera::cx, &plumb::DepthCamera::cy,
        &plumb::DepthCamera::k1, &plumb::DepthCamera::k2, &plumb::DepthCamera::p1, &plumb::DepthCamera::p2,
        &plumb::DepthCamera::k3, &plumb::DepthCamera::qx, &plumb::DepthCamera::qy, &plumb::DepthCamera::qz,
        &plumb::DepthCamera::qw, &plumb::DepthCamera::tx, &plumb::DepthCamera::ty, &plumb::DepthCamera::tz};
    for (auto field : depth_reals) FUZZ_CHECK(sameBits(b.*field, a.*field));
    FUZZ_CHECK(b.width == a.width && b.height == a.height);
  }
  return 0;
}

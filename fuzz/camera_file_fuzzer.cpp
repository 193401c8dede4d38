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
  return 0;
}

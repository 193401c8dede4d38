// libFuzzer target for the TUM trajectory reader (drivers/trajectory/trajectory_io.h). The first
// input byte picks the read options (lost markers kept or not, norm tolerance); the rest is the
// file. Beyond "no crash", an accepted trajectory must keep the reader's promises:
//  - at least one pose, finite timestamps strictly increasing (duplicates replaced), rotations
//    orthonormal with determinant 1, finite translations;
//  - written with formatTumLine() and read again it gives the same poses within the printed
//    precision (%.6f timestamps, %.9g numbers).
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "drivers/trajectory/trajectory_io.h"
#include "fuzz/fuzz_support.h"

namespace {

using plumb::StampedPose;
using plumb::fuzz::MemFile;

void checkPoses(const std::vector<StampedPose>& poses, bool keep_lost) {
  FUZZ_CHECK(!poses.empty());
  bool any_valid = false;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const StampedPose& p = poses[i];
    FUZZ_CHECK(std::isfinite(p.timestamp));
    if (i > 0) FUZZ_CHECK(p.timestamp > poses[i - 1].timestamp);
    if (!p.valid) {
      FUZZ_CHECK(keep_lost);
      continue;
    }
    any_valid = true;
    const Eigen::Matrix3d R = p.T_world_cam.linear();
    FUZZ_CHECK((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-9);
    FUZZ_CHECK(std::abs(R.determinant() - 1.0) < 1e-9);
    FUZZ_CHECK(p.T_world_cam.translation().allFinite());
  }
  FUZZ_CHECK(any_valid);
}

std::string format(const std::vector<StampedPose>& poses) {
  std::string text;
  for (const StampedPose& p : poses) text += plumb::formatTumLine(p) + "\n";
  return text;
}

bool read(const std::string& text, const plumb::TrajectoryReadOptions& options, std::vector<StampedPose>* out) {
  MemFile file(text);
  return file.ok() && plumb::readTumTrajectory(file.path(), out, options).ok();
}

std::string stampText(double t) {
  char text[400];
  std::snprintf(text, sizeof(text), "%.6f", t);
  return text;
}

// |a - b| within what `%.Ng` printing of a (or b) may lose, plus an absolute floor.
bool close(double a, double b, double relative, double absolute) {
  return std::abs(a - b) <= absolute + relative * std::max(std::abs(a), std::abs(b));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  plumb::TrajectoryReadOptions options;
  options.keep_lost_markers = (data[0] & 1) != 0;
  options.quaternion_norm_tolerance = (data[0] & 2) != 0 ? 0.05 : 1e-3;
  MemFile file(data + 1, size - 1);
  if (!file.ok()) return 0;
  std::vector<StampedPose> poses;
  plumb::TrajectoryReadReport report;
  if (!plumb::readTumTrajectory(file.path(), &poses, options, &report).ok()) return 0;
  FUZZ_CHECK(report.duplicate_timestamps_replaced >= 0 && report.quaternions_normalised >= 0);
  checkPoses(poses, options.keep_lost_markers);

  // What plumb would write, read back. Timestamps print as %.6f, so stamps closer than that
  // merge into duplicates (the later wins, possibly a lost marker): not compared.
  for (std::size_t i = 1; i < poses.size(); ++i)
    if (std::strtod(stampText(poses[i].timestamp).c_str(), nullptr) ==
        std::strtod(stampText(poses[i - 1].timestamp).c_str(), nullptr))  // "-0.000000" == "0.000000"
      return 0;
  const std::string first_text = format(poses);
  std::vector<StampedPose> first;
  FUZZ_CHECK(read(first_text, options, &first));
  checkPoses(first, options.keep_lost_markers);
  FUZZ_CHECK(first.size() == poses.size());
  {
    for (std::size_t i = 0; i < poses.size(); ++i) {
      FUZZ_CHECK(first[i].valid == poses[i].valid && first[i].dropped == poses[i].dropped);
      FUZZ_CHECK(close(first[i].timestamp, poses[i].timestamp, 1e-15, 5.1e-7));
      if (!poses[i].valid) continue;
      for (int k = 0; k < 3; ++k)
        FUZZ_CHECK(close(first[i].T_world_cam.translation()[k], poses[i].T_world_cam.translation()[k], 1e-8, 1e-300));
      const Eigen::Matrix3d dR = first[i].T_world_cam.linear().transpose() * poses[i].T_world_cam.linear();
      FUZZ_CHECK((dR - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-7);
    }
  }
  return 0;
}

#include "drivers/trajectory/covariance_io.h"

#include <cmath>

namespace plumb {
namespace {

constexpr const char* kKeyframeHeader = "# plumb keyframe pose covariance";
constexpr const char* kTrackedHeader = "# plumb tracked pose covariance";

void printUpper(std::FILE* out, const Eigen::Matrix<double, 6, 6>& c) {
  for (int r = 0; r < 6; ++r) {
    for (int k = r; k < 6; ++k) std::fprintf(out, " %.9g", c(r, k));
  }
}

void printPose(std::FILE* out, const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.rotation());
  const Eigen::Vector3d& t = T.translation();
  std::fprintf(out, " %.9g %.9g %.9g %.9g %.9g %.9g %.9g", t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
}

}  // namespace

CovarianceWriter::~CovarianceWriter() = default;  // an uncommitted file is abandoned

Status CovarianceWriter::open(const std::string& path, CovarianceFileKind kind) {
  PLUMB_RETURN_IF_ERROR(file_.open(path));
  path_ = path;
  kind_ = kind;
  if (kind == CovarianceFileKind::kKeyframe) {
    std::fprintf(file_.file(),
                 "%s: timestamp then the 21 upper-triangle entries of the 6x6\n"
                 "# covariance of the left perturbation [rho(3) phi(3)] of T_cam_world, row by row; optionally\n"
                 "# then the previous keyframe's timestamp, T_previous_this (tx ty tz qx qy qz qw) and the 21\n"
                 "# entries of its right-perturbation covariance from local BA's joint marginal\n",
                 kKeyframeHeader);
  } else {
    std::fprintf(file_.file(),
                 "%s: timestamp tx ty tz qx qy qz qw (T_world_cam as tracked), then the 21\n"
                 "# upper-triangle entries of the 6x6 covariance of the left perturbation [rho(3) phi(3)] of\n"
                 "# T_cam_world with respect to the world frame, then 21 of it relative to the map; optionally\n"
                 "# then the previous frame's timestamp and its pose in this frame's map (tx ty tz qx qy qz qw),\n"
                 "# from which MAVLink's velocity is made\n",
                 kTrackedHeader);
  }
  return Status::Ok();
}

Status CovarianceWriter::append(const StampedCovariance& kf) {
  if (!file_.isOpen() || kind_ != CovarianceFileKind::kKeyframe) return Status::Error("keyframe covariance file is not open");
  std::FILE* out = file_.file();
  if (!kf.valid) {
    std::fprintf(out, "# %.6f no covariance\n", kf.timestamp);
    return Status::Ok();
  }
  std::fprintf(out, "%.6f", kf.timestamp);
  printUpper(out, kf.covariance);
  if (kf.has_relative) {
    std::fprintf(out, " %.6f", kf.previous_timestamp);
    printPose(out, kf.T_previous_this);
    printUpper(out, kf.relative_covariance);
  }
  std::fprintf(out, "\n");
  return Status::Ok();
}

Status CovarianceWriter::append(const StampedTrackedCovariance& f) {
  if (!file_.isOpen() || kind_ != CovarianceFileKind::kTracked) return Status::Error("tracked covariance file is not open");
  std::FILE* out = file_.file();
  if (!f.valid) {
    std::fprintf(out, "# %.6f no covariance\n", f.timestamp);
    return Status::Ok();
  }
  std::fprintf(out, "%.6f", f.timestamp);
  printPose(out, f.T_world_cam);
  printUpper(out, f.covariance);
  printUpper(out, f.covariance_local);
  if (f.has_previous) {
    std::fprintf(out, " %.6f", f.previous_timestamp);
    printPose(out, f.T_world_previous);
  }
  std::fprintf(out, "\n");
  return Status::Ok();
}

Status CovarianceWriter::close() {
  if (!file_.isOpen()) return Status::Ok();
  return file_.commit();
}

}  // namespace plumb

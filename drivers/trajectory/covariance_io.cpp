#include "drivers/trajectory/covariance_io.h"

namespace plumb {

CovarianceWriter::~CovarianceWriter() { (void)close(); }

Status CovarianceWriter::open(const std::string& path) {
  file_ = std::fopen(path.c_str(), "w");
  if (file_ == nullptr) return Status::Error(path + ": cannot open for writing");
  path_ = path;
  std::fprintf(file_,
               "# plumb keyframe pose covariance: timestamp then the 21 upper-triangle entries of the 6x6\n"
               "# covariance of the left perturbation [rho(3) phi(3)] of T_cam_world, row by row\n");
  return Status::Ok();
}

Status CovarianceWriter::append(const StampedCovariance& kf) {
  if (file_ == nullptr) return Status::Error("covariance file is not open");
  if (!kf.valid) {
    std::fprintf(file_, "# %.6f no covariance\n", kf.timestamp);
    return Status::Ok();
  }
  std::fprintf(file_, "%.6f", kf.timestamp);
  for (int r = 0; r < 6; ++r) {
    for (int c = r; c < 6; ++c) std::fprintf(file_, " %.9g", kf.covariance(r, c));
  }
  std::fprintf(file_, "\n");
  return Status::Ok();
}

Status CovarianceWriter::close() {
  if (file_ == nullptr) return Status::Ok();
  const bool ok = std::fclose(file_) == 0;
  file_ = nullptr;
  return ok ? Status::Ok() : Status::Error(path_ + ": write failed");
}

}  // namespace plumb

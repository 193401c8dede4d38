#include "drivers/trajectory/covariance_io.h"

namespace plumb {

CovarianceWriter::~CovarianceWriter() = default;  // an uncommitted file is abandoned

Status CovarianceWriter::open(const std::string& path) {
  PLUMB_RETURN_IF_ERROR(file_.open(path));
  path_ = path;
  std::fprintf(file_.file(),
               "# plumb keyframe pose covariance: timestamp then the 21 upper-triangle entries of the 6x6\n"
               "# covariance of the left perturbation [rho(3) phi(3)] of T_cam_world, row by row\n");
  return Status::Ok();
}

Status CovarianceWriter::append(const StampedCovariance& kf) {
  if (!file_.isOpen()) return Status::Error("covariance file is not open");
  std::FILE* out = file_.file();
  if (!kf.valid) {
    std::fprintf(out, "# %.6f no covariance\n", kf.timestamp);
    return Status::Ok();
  }
  std::fprintf(out, "%.6f", kf.timestamp);
  for (int r = 0; r < 6; ++r) {
    for (int c = r; c < 6; ++c) std::fprintf(out, " %.9g", kf.covariance(r, c));
  }
  std::fprintf(out, "\n");
  return Status::Ok();
}

Status CovarianceWriter::close() {
  if (!file_.isOpen()) return Status::Ok();
  return file_.commit();
}

}  // namespace plumb

#pragma once
// Keyframe covariance file (docs/DATA_FORMATS.md): `timestamp c00 c01 .. c05 c11 .. c55` (the 21
// upper-triangle entries of the 6x6 covariance of the left perturbation [rho(3) phi(3)] of
// T_cam_world, row by row) per keyframe, in the order keyframes leave the map; a keyframe local BA
// never gave a covariance is written as `# <timestamp> no covariance`.
#include <cstdio>
#include <string>

#include <Eigen/Core>

#include "drivers/common/atomic_file.h"
#include "platform/status.h"

namespace plumb {

struct StampedCovariance {
  double timestamp = 0;
  bool valid = false;
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
};

class CovarianceWriter {
 public:
  CovarianceWriter() = default;
  ~CovarianceWriter();
  CovarianceWriter(const CovarianceWriter&) = delete;
  CovarianceWriter& operator=(const CovarianceWriter&) = delete;

  Status open(const std::string& path);
  Status append(const StampedCovariance& keyframe);  // allocates nothing
  Status close();
  void abandon() { file_.abandon(); }  // nothing appears under the name (an older file stays)

 private:
  std::string path_;
  AtomicFile file_;  // appears under path_ only when closed (complete)
};

}  // namespace plumb

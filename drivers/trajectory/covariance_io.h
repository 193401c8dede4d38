#pragma once
// Pose covariance files (docs/DATA_FORMATS.md "Covariance files"). Every 6x6 is the covariance of
// a perturbation [rho(3) phi(3)] in solver/se3.h's order, written as its 21 upper-triangle entries
// row by row (c00 c01 .. c05 c11 .. c55).
//
// KEYFRAME file (`plumb run --covariance`), one line per keyframe as it leaves the map:
//   timestamp  c00..c55                                       (22 fields: marginal only)
//   timestamp  c00..c55  t_prev tx ty tz qx qy qz qw  r00..r55 (51 fields)
// c: the keyframe's marginal from its last local BA (left perturbation of T_cam_world; gauge: the
// keyframes that BA held fixed). The optional tail: the relative pose to the previous keyframe
// (stamped t_prev) T_previous_this = T_cam_prev_world * T_cam_this_world^-1 as that BA left them
// (translation, then quaternion x y z w), and r, the covariance of its RIGHT perturbation from the
// BA's joint marginal (solver/pose_covariance.h). Readers of the 22-field form read the first 22
// fields of either. `# <timestamp> no covariance`: a keyframe local BA never gave one.
//
// TRACKED file (`plumb run --track-covariance`), one line per tracked frame:
//   timestamp  tx ty tz qx qy qz qw  w00..w55  l00..l55       (50 fields)
// The pose as tracked (T_world_cam, TUM order: what MAVLink sends), w its covariance with respect
// to the world frame (left perturbation of T_cam_world: what MAVLink sends, before the change to
// the body frame), l the same pose's covariance relative to the map (what the velocity's builds
// on). `# <timestamp> no covariance`: a frame with a pose but no covariance; frames without a pose
// have no line. Both files start with a `# plumb keyframe pose covariance` / `# plumb tracked pose
// covariance` comment, which readers use to tell them apart.
#include <cstdio>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "drivers/common/atomic_file.h"
#include "platform/status.h"
#include "sensor/stamped_covariance.h"

namespace plumb {

enum class CovarianceFileKind { kKeyframe, kTracked };

class CovarianceWriter {
 public:
  CovarianceWriter() = default;
  ~CovarianceWriter();
  CovarianceWriter(const CovarianceWriter&) = delete;
  CovarianceWriter& operator=(const CovarianceWriter&) = delete;

  Status open(const std::string& path, CovarianceFileKind kind = CovarianceFileKind::kKeyframe);
  Status append(const StampedCovariance& keyframe);         // allocates nothing
  Status append(const StampedTrackedCovariance& frame);     // allocates nothing
  Status close();
  void abandon() { file_.abandon(); }  // nothing appears under the name (an older file stays)

 private:
  std::string path_;
  CovarianceFileKind kind_ = CovarianceFileKind::kKeyframe;
  AtomicFile file_;  // appears under path_ only when closed (complete)
};

// What a covariance file holds; exactly one of the vectors is filled, by `kind` (the header
// comment; a file without one is read as a keyframe file). Errors name file and line: wrong field
// count, unparsable or non-finite numbers, a quaternion far from unit norm, a matrix that is not
// symmetric positive semi-definite.
struct CovarianceFile {
  CovarianceFileKind kind = CovarianceFileKind::kKeyframe;
  std::vector<StampedCovariance> keyframes;
  std::vector<StampedTrackedCovariance> frames;
};
Status readCovarianceFile(const std::string& path, CovarianceFile* out);

}  // namespace plumb

#pragma once
// TUM trajectory files: `timestamp tx ty tz qx qy qz qw` per line, the pose T_world_cam (camera
// optical centre and orientation in the world frame, qw last). `#` lines are comments; commas and
// tabs are accepted as separators, like the benchmark's scripts.
//
// plumb writes one line per input frame. A frame without a pose (tracking lost, not initialised)
// is written as the comment line `# <timestamp> lost`, so the benchmark tools still parse the file
// and simply see no pose at that time. See docs/DATA_FORMATS.md.
#include <Eigen/Geometry>
#include <cstdio>
#include <string>
#include <vector>

#include "drivers/common/atomic_file.h"
#include "platform/status.h"
#include "sensor/stamped_pose.h"

namespace plumb {

struct TrajectoryReadOptions {
  // A quaternion whose norm is within this of 1 is normalised (files print 4-9 digits); further
  // away, or zero, is an error.
  double quaternion_norm_tolerance = 0.05;
  // Return `# <timestamp> lost` markers as StampedPose{valid=false}; otherwise skip them.
  bool keep_lost_markers = false;
};

struct TrajectoryReadReport {
  // Lines whose timestamp equals the previous one. The benchmark reads files into a dictionary,
  // so the later line wins; we do the same and count them (fr2/desk's ground truth has one).
  int duplicate_timestamps_replaced = 0;
  int quaternions_normalised = 0;  // norms off by more than 1e-6 that were normalised
};

// Errors name file and line: wrong column count, unparsable or non-finite numbers, zero or
// far-from-unit quaternions, decreasing timestamps, no poses at all.
Status readTumTrajectory(const std::string& path, std::vector<StampedPose>* out,
                         const TrajectoryReadOptions& options = {}, TrajectoryReadReport* report = nullptr);

// One line for a pose: `%.6f` timestamp, `%.9g` numbers, or `# %.6f lost` when !valid.
// Deterministic bytes (C locale number formatting, no trailing spaces), no newline.
std::string formatTumLine(const StampedPose& pose);

// The same bytes into a caller's buffer (no heap allocation, for the per-frame writer); returns
// the length, truncating to buffer_size - 1. kTumLineCapacity always fits a whole line: the
// longest is a %.6f timestamp of -DBL_MAX (317 characters) and seven %.9g numbers of at most 16
// ("-1.23456789e+308") with their spaces, 436 in all (the reader accepts any finite value).
constexpr std::size_t kTumLineCapacity = 512;
std::size_t formatTumLine(const StampedPose& pose, char* buffer, std::size_t buffer_size);

// Writes the header comment and one line per pose.
Status writeTumTrajectory(const std::string& path, const std::vector<StampedPose>& poses);

// Streaming writer for a running system: append() per frame, flushed on close()/destruction.
class TumTrajectoryWriter {
 public:
  TumTrajectoryWriter() = default;
  ~TumTrajectoryWriter();
  TumTrajectoryWriter(const TumTrajectoryWriter&) = delete;
  TumTrajectoryWriter& operator=(const TumTrajectoryWriter&) = delete;

  Status open(const std::string& path);
  Status append(const StampedPose& pose);  // allocates nothing
  Status close();
  void abandon() { file_.abandon(); }  // nothing appears under the name (an older file stays)

 private:
  std::string path_;
  AtomicFile file_;  // appears under path_ only when closed (complete)
};

}  // namespace plumb

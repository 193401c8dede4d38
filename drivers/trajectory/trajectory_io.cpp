#include "drivers/trajectory/trajectory_io.h"

#include <cerrno>
#include <cmath>
#include <cstring>

#include "drivers/common/text_lines.h"

namespace plumb {
namespace {

std::string formatNumber(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

// `# <timestamp> lost` or `# <timestamp> dropped` as written by formatTumLine for a frame without
// a pose (tracking lost, or never processed because the real-time mode had no free slot).
bool parseLostMarker(const TextLine& line, double* timestamp, bool* dropped) {
  if (!line.is_comment || line.tokens.size() != 2) return false;
  if (line.tokens[1] != "lost" && line.tokens[1] != "dropped") return false;
  *dropped = line.tokens[1] == "dropped";
  return parseDouble(line.tokens[0], timestamp) && std::isfinite(*timestamp);
}

Status parsePoseLine(const std::string& where, const TextLine& line, const TrajectoryReadOptions& options,
                     StampedPose* pose, bool* normalised) {
  if (line.tokens.size() != 8)
    return Status::Error(where + ": expected 8 fields `timestamp tx ty tz qx qy qz qw`, got " +
                         std::to_string(line.tokens.size()));
  double v[8];
  static const char* const kNames[8] = {"timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};
  for (int i = 0; i < 8; ++i) {
    if (!parseDouble(line.tokens[i], &v[i]))
      return Status::Error(where + ": " + kNames[i] + " '" + line.tokens[i] + "' is not a number");
    if (!std::isfinite(v[i])) return Status::Error(where + ": " + kNames[i] + " is not finite");
  }
  Eigen::Quaterniond q_world_cam(v[7], v[4], v[5], v[6]);  // Eigen's constructor is (w, x, y, z)
  const double norm = q_world_cam.norm();
  if (norm < 1e-9) return Status::Error(where + ": zero quaternion");
  if (std::abs(norm - 1.0) > options.quaternion_norm_tolerance)
    return Status::Error(where + ": quaternion norm " + formatNumber("%.6g", norm) + " is not 1 (tolerance " +
                         formatNumber("%g", options.quaternion_norm_tolerance) + ")");
  *normalised = std::abs(norm - 1.0) > 1e-6;
  q_world_cam.normalize();
  pose->timestamp = v[0];
  pose->T_world_cam.setIdentity();
  pose->T_world_cam.linear() = q_world_cam.toRotationMatrix();
  pose->T_world_cam.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
  pose->valid = true;
  return Status::Ok();
}

}  // namespace

Status readTumTrajectory(const std::string& path, std::vector<StampedPose>* out,
                         const TrajectoryReadOptions& options, TrajectoryReadReport* report) {
  out->clear();
  TrajectoryReadReport local_report;
  int previous_line = 0;
  std::size_t valid_poses = 0;
  // Streamed (drivers/common/text_lines.h): memory holds the poses, never the file's text.
  PLUMB_RETURN_IF_ERROR(forEachTextLine(path, [&](const TextLine& line, Status* error) {
    const std::string where = fileLine(path, line.number);
    StampedPose pose;
    if (line.is_comment) {
      if (!parseLostMarker(line, &pose.timestamp, &pose.dropped) || !options.keep_lost_markers) return true;
      pose.valid = false;
    } else {
      bool normalised = false;
      *error = parsePoseLine(where, line, options, &pose, &normalised);
      if (!error->ok()) return false;
      local_report.quaternions_normalised += normalised ? 1 : 0;
    }
    if (!out->empty()) {
      const double previous = out->back().timestamp;
      if (pose.timestamp < previous) {
        *error = Status::Error(where + ": non-monotonic timestamp " + formatNumber("%.6f", pose.timestamp) +
                               " (previous " + formatNumber("%.6f", previous) + " on line " +
                               std::to_string(previous_line) + ")");
        return false;
      }
      if (pose.timestamp == previous) {
        // The benchmark's dictionary keeps the later line; so do we, and count it.
        ++local_report.duplicate_timestamps_replaced;
        if (out->back().valid) --valid_poses;
        out->pop_back();
      }
    }
    valid_poses += pose.valid ? 1 : 0;
    previous_line = line.number;
    out->push_back(pose);
    return true;
  }));
  if (valid_poses == 0) return Status::Error(path + ": no poses (empty trajectory)");
  if (report) *report = local_report;
  return Status::Ok();
}

std::size_t formatTumLine(const StampedPose& pose, char* buffer, std::size_t buffer_size) {
  if (buffer_size == 0) return 0;
  int written = 0;
  if (!pose.valid) {
    written = std::snprintf(buffer, buffer_size, pose.dropped ? "# %.6f dropped" : "# %.6f lost", pose.timestamp);
  } else {
    const Eigen::Vector3d t = pose.T_world_cam.translation();
    Eigen::Quaterniond q(pose.T_world_cam.rotation());
    // q and -q are the same rotation; pick qw >= 0 so equal poses always print the same bytes.
    if (q.w() < 0) q.coeffs() = -q.coeffs();
    written = std::snprintf(buffer, buffer_size, "%.6f %.9g %.9g %.9g %.9g %.9g %.9g %.9g", pose.timestamp, t.x(),
                            t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  }
  if (written < 0) written = 0;
  return static_cast<std::size_t>(written) < buffer_size ? static_cast<std::size_t>(written) : buffer_size - 1;
}

std::string formatTumLine(const StampedPose& pose) {
  char text[kTumLineCapacity];
  const std::size_t length = formatTumLine(pose, text, sizeof(text));
  return std::string(text, length);
}

Status writeTumTrajectory(const std::string& path, const std::vector<StampedPose>& poses) {
  TumTrajectoryWriter writer;
  PLUMB_RETURN_IF_ERROR(writer.open(path));
  for (const StampedPose& pose : poses) PLUMB_RETURN_IF_ERROR(writer.append(pose));
  return writer.close();
}

TumTrajectoryWriter::~TumTrajectoryWriter() = default;  // an uncommitted file is abandoned

Status TumTrajectoryWriter::open(const std::string& path) {
  if (file_.isOpen()) return Status::Error(path_ + ": trajectory writer already open");
  path_ = path;
  PLUMB_RETURN_IF_ERROR(file_.open(path));
  std::fputs(
      "# plumb trajectory: timestamp tx ty tz qx qy qz qw (T_world_cam); "
      "'# <timestamp> lost' = no pose\n",
      file_.file());
  return Status::Ok();
}

Status TumTrajectoryWriter::append(const StampedPose& pose) {
  if (!file_.isOpen()) return Status::Error("trajectory writer is not open");
  char line[kTumLineCapacity];
  formatTumLine(pose, line, sizeof(line));
  if (std::fprintf(file_.file(), "%s\n", line) < 0) return Status::Error(path_ + ": write failed");
  return Status::Ok();
}

Status TumTrajectoryWriter::close() {
  if (!file_.isOpen()) return Status::Ok();
  return file_.commit();
}

}  // namespace plumb

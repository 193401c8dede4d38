// readCovarianceFile (drivers/trajectory/covariance_io.h): both kinds of covariance file.
#include <cmath>

#include <Eigen/Eigenvalues>

#include "drivers/common/text_lines.h"
#include "drivers/trajectory/covariance_io.h"

namespace plumb {
namespace {

// Numbers of `line` from `first`, `count` of them, finite.
Status parseNumbers(const std::string& where, const TextLine& line, std::size_t first, std::size_t count, double* out) {
  for (std::size_t i = 0; i < count; ++i) {
    const std::string& token = line.tokens[first + i];
    if (!parseDouble(token, &out[i])) return Status::Error(where + ": field " + std::to_string(first + i + 1) + " '" + token + "' is not a number");
    if (!std::isfinite(out[i])) return Status::Error(where + ": field " + std::to_string(first + i + 1) + " is not finite");
  }
  return Status::Ok();
}

Status parseUpper(const std::string& where, const TextLine& line, std::size_t first, const char* what,
                  Eigen::Matrix<double, 6, 6>* out) {
  double v[21];
  PLUMB_RETURN_IF_ERROR(parseNumbers(where, line, first, 21, v));
  int k = 0;
  for (int r = 0; r < 6; ++r) {
    for (int c = r; c < 6; ++c) (*out)(r, c) = (*out)(c, r) = v[k++];
  }
  // Positive semi-definite up to the 9 printed digits.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(*out, Eigen::EigenvaluesOnly);
  const double largest = eig.eigenvalues().cwiseAbs().maxCoeff();
  if (eig.eigenvalues().minCoeff() < -1e-6 * largest)
    return Status::Error(where + ": " + what + " is not positive semi-definite");
  return Status::Ok();
}

Status parsePose(const std::string& where, const TextLine& line, std::size_t first, Eigen::Isometry3d* T) {
  double v[7];
  PLUMB_RETURN_IF_ERROR(parseNumbers(where, line, first, 7, v));
  Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  if (std::abs(q.norm() - 1.0) > 0.05) return Status::Error(where + ": quaternion norm is not 1");
  q.normalize();
  T->setIdentity();
  T->linear() = q.toRotationMatrix();
  T->translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  return Status::Ok();
}

bool isNoCovarianceMarker(const TextLine& line, double* timestamp) {
  return line.is_comment && line.tokens.size() == 3 && line.tokens[1] == "no" && line.tokens[2] == "covariance" &&
         parseDouble(line.tokens[0], timestamp) && std::isfinite(*timestamp);
}

}  // namespace

Status readCovarianceFile(const std::string& path, CovarianceFile* out) {
  *out = CovarianceFile{};
  std::vector<TextLine> lines;
  PLUMB_RETURN_IF_ERROR(readTextLines(path, &lines));
  if (!lines.empty() && lines[0].is_comment && lines[0].tokens.size() >= 3 && lines[0].tokens[0] == "plumb" &&
      lines[0].tokens[1] == "tracked") {
    out->kind = CovarianceFileKind::kTracked;
  }
  const bool tracked = out->kind == CovarianceFileKind::kTracked;
  for (const TextLine& line : lines) {
    const std::string where = fileLine(path, line.number);
    double t = 0;
    if (line.is_comment) {
      if (!isNoCovarianceMarker(line, &t)) continue;
      if (tracked) {
        StampedTrackedCovariance f;
        f.timestamp = t;
        out->frames.push_back(f);
      } else {
        StampedCovariance k;
        k.timestamp = t;
        out->keyframes.push_back(k);
      }
      continue;
    }
    const std::size_t n = line.tokens.size();
    if (tracked) {
      if (n != 50 && n != 58) {
        return Status::Error(where + ": expected 50 fields (timestamp, pose, 2 x 21 covariance entries) or 58 (and the previous frame's timestamp and pose), got " + std::to_string(n));
      }
      StampedTrackedCovariance f;
      PLUMB_RETURN_IF_ERROR(parseNumbers(where, line, 0, 1, &f.timestamp));
      PLUMB_RETURN_IF_ERROR(parsePose(where, line, 1, &f.T_world_cam));
      PLUMB_RETURN_IF_ERROR(parseUpper(where, line, 8, "the world covariance", &f.covariance));
      PLUMB_RETURN_IF_ERROR(parseUpper(where, line, 29, "the local covariance", &f.covariance_local));
      if (n == 58) {
        PLUMB_RETURN_IF_ERROR(parseNumbers(where, line, 50, 1, &f.previous_timestamp));
        PLUMB_RETURN_IF_ERROR(parsePose(where, line, 51, &f.T_world_previous));
        f.has_previous = true;
      }
      f.valid = true;
      out->frames.push_back(f);
      continue;
    }
    if (n != 22 && n != 51) return Status::Error(where + ": expected 22 or 51 fields, got " + std::to_string(n));
    StampedCovariance k;
    PLUMB_RETURN_IF_ERROR(parseNumbers(where, line, 0, 1, &k.timestamp));
    PLUMB_RETURN_IF_ERROR(parseUpper(where, line, 1, "the marginal covariance", &k.covariance));
    k.valid = true;
    if (n == 51) {
      PLUMB_RETURN_IF_ERROR(parseNumbers(where, line, 22, 1, &k.previous_timestamp));
      PLUMB_RETURN_IF_ERROR(parsePose(where, line, 23, &k.T_previous_this));
      PLUMB_RETURN_IF_ERROR(parseUpper(where, line, 30, "the relative covariance", &k.relative_covariance));
      k.has_relative = true;
    }
    out->keyframes.push_back(k);
  }
  if (out->keyframes.empty() && out->frames.empty()) return Status::Error(path + ": no covariances");
  return Status::Ok();
}

}  // namespace plumb

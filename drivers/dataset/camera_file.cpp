#include "drivers/dataset/camera_file.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>

#include "drivers/common/text_lines.h"

namespace plumb {
namespace {

// Where each key's value goes; integers are stored through `int_field`.
struct CameraKey {
  double* real_field = nullptr;
  int* int_field = nullptr;
  bool required = false;
  bool must_be_nonzero = false;
};

std::map<std::string, CameraKey> cameraKeys(PinholeCamera* c) {
  return {
      {"fx", {&c->fx, nullptr, true, true}},
      {"fy", {&c->fy, nullptr, true, true}},
      {"cx", {&c->cx, nullptr, true, false}},
      {"cy", {&c->cy, nullptr, true, false}},
      {"k1", {&c->k1, nullptr, false, false}},
      {"k2", {&c->k2, nullptr, false, false}},
      {"p1", {&c->p1, nullptr, false, false}},
      {"p2", {&c->p2, nullptr, false, false}},
      {"k3", {&c->k3, nullptr, false, false}},
      {"width", {nullptr, &c->width, false, true}},
      {"height", {nullptr, &c->height, false, true}},
      {"depth_factor", {&c->depth_factor, nullptr, false, true}},
      {"baseline", {&c->baseline_m, nullptr, false, true}},
      {"rolling_shutter_readout", {&c->rolling_shutter_readout_s, nullptr, false, false}},
  };
}

}  // namespace

Status readCameraFile(const std::string& path, PinholeCamera* out) {
  std::vector<TextLine> lines;
  PLUMB_RETURN_IF_ERROR(readTextLines(path, &lines, kMaxCameraFileBytes).withContext("camera file"));
  PinholeCamera camera;  // defaults: no distortion, 640x480, depth factor 5000, baseline 0.08
  const std::map<std::string, CameraKey> keys = cameraKeys(&camera);
  std::map<std::string, int> seen_on_line;
  for (const TextLine& line : lines) {
    if (line.is_comment) continue;
    const std::string where = fileLine(path, line.number);
    if (line.tokens.size() != 2)
      return Status::Error(where + ": expected `key value`, got " + std::to_string(line.tokens.size()) +
                           " fields");
    const std::string& key = line.tokens[0];
    const std::string& text = line.tokens[1];
    auto it = keys.find(key);
    if (it == keys.end()) return Status::Error(where + ": unknown key '" + key + "'");
    if (seen_on_line.count(key))
      return Status::Error(where + ": key '" + key + "' repeated (first on line " +
                           std::to_string(seen_on_line[key]) + ")");
    seen_on_line[key] = line.number;
    const CameraKey& target = it->second;
    if (target.int_field) {
      int value = 0;
      if (!parseInt(text, &value))
        return Status::Error(where + ": " + key + " '" + text + "' is not an integer");
      if (value <= 0) return Status::Error(where + ": " + key + " must be positive");
      *target.int_field = value;
      continue;
    }
    double value = 0;
    if (!parseDouble(text, &value))
      return Status::Error(where + ": " + key + " '" + text + "' is not a number");
    if (!std::isfinite(value)) return Status::Error(where + ": " + key + " is not finite");
    if (target.must_be_nonzero && value == 0) return Status::Error(where + ": " + key + " is zero");
    *target.real_field = value;
  }
  for (const auto& [key, target] : keys) {
    if (target.required && !seen_on_line.count(key))
      return Status::Error(path + ": missing required key '" + key + "'");
  }
  const std::string problem = camera.validate();
  if (!problem.empty()) return Status::Error(path + ": " + problem);
  *out = camera;
  return Status::Ok();
}

Status writeCameraFile(const std::string& path, const PinholeCamera& camera) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) return Status::Error(path + ": cannot write (" + std::strerror(errno) + ")");
  std::fprintf(file, "# plumb camera file (docs/DATA_FORMATS.md)\n");
  const struct {
    const char* key;
    double value;
  } reals[] = {{"fx", camera.fx}, {"fy", camera.fy}, {"cx", camera.cx}, {"cy", camera.cy}, {"k1", camera.k1},
               {"k2", camera.k2}, {"p1", camera.p1}, {"p2", camera.p2}, {"k3", camera.k3}};
  for (const auto& r : reals) std::fprintf(file, "%s %.17g\n", r.key, r.value);
  std::fprintf(file, "width %d\nheight %d\n", camera.width, camera.height);
  std::fprintf(file, "depth_factor %.17g\nbaseline %.17g\n", camera.depth_factor, camera.baseline_m);
  // Written even when 0 (global shutter) so a folder exported from a recording replays the same.
  std::fprintf(file, "rolling_shutter_readout %.17g\n", camera.rolling_shutter_readout_s);
  const bool write_failed = std::ferror(file) != 0;
  if (std::fclose(file) != 0 || write_failed) return Status::Error(path + ": write failed");
  return Status::Ok();
}

}  // namespace plumb

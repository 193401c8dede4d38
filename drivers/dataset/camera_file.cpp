#include "drivers/dataset/camera_file.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <initializer_list>
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

// Keys of the unregistered depth camera (docs/DATA_FORMATS.md "Unregistered depth"). Any one of
// them makes the depth unregistered, and then every key marked required here must be given too:
// an extrinsic left out would silently become the identity.
std::map<std::string, CameraKey> depthCameraKeys(DepthCamera* d) {
  return {
      {"depth_fx", {&d->fx, nullptr, true, true}},
      {"depth_fy", {&d->fy, nullptr, true, true}},
      {"depth_cx", {&d->cx, nullptr, true, false}},
      {"depth_cy", {&d->cy, nullptr, true, false}},
      {"depth_k1", {&d->k1, nullptr, false, false}},
      {"depth_k2", {&d->k2, nullptr, false, false}},
      {"depth_p1", {&d->p1, nullptr, false, false}},
      {"depth_p2", {&d->p2, nullptr, false, false}},
      {"depth_k3", {&d->k3, nullptr, false, false}},
      {"depth_width", {nullptr, &d->width, true, true}},
      {"depth_height", {nullptr, &d->height, true, true}},
      {"depth_to_colour_qx", {&d->qx, nullptr, true, false}},
      {"depth_to_colour_qy", {&d->qy, nullptr, true, false}},
      {"depth_to_colour_qz", {&d->qz, nullptr, true, false}},
      {"depth_to_colour_qw", {&d->qw, nullptr, true, false}},
      {"depth_to_colour_tx", {&d->tx, nullptr, true, false}},
      {"depth_to_colour_ty", {&d->ty, nullptr, true, false}},
      {"depth_to_colour_tz", {&d->tz, nullptr, true, false}},
  };
}

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
  DepthCamera depth;     // used only when a depth_* key is present
  std::map<std::string, CameraKey> keys = cameraKeys(&camera);
  const std::map<std::string, CameraKey> depth_keys = depthCameraKeys(&depth);
  keys.insert(depth_keys.begin(), depth_keys.end());
  std::map<std::string, int> seen_on_line;
  int first_depth_line = 0;
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
    if (depth_keys.count(key) && first_depth_line == 0) first_depth_line = line.number;
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
  for (const auto& [key, target] : cameraKeys(&camera)) {
    if (target.required && !seen_on_line.count(key))
      return Status::Error(path + ": missing required key '" + key + "'");
  }
  if (first_depth_line != 0) {
    for (const auto& [key, target] : depth_keys) {
      if (target.required && !seen_on_line.count(key))
        return Status::Error(path + ": missing key '" + key + "': line " + std::to_string(first_depth_line) +
                             " describes an unregistered depth camera, which needs depth_fx depth_fy depth_cx "
                             "depth_cy depth_width depth_height and the whole depth_to_colour transform "
                             "(qx qy qz qw tx ty tz)");
    }
    camera.depth_camera = depth;
  }
  const std::string problem = camera.validate();
  if (!problem.empty()) return Status::Error(path + ": " + problem);
  *out = camera;
  return Status::Ok();
}

namespace {

struct KeyValue {
  const char* key;
  double value;
};

void writeReals(std::FILE* file, std::initializer_list<KeyValue> reals) {
  for (const KeyValue& r : reals) std::fprintf(file, "%s %.17g\n", r.key, r.value);
}

}  // namespace

Status writeCameraFile(const std::string& path, const PinholeCamera& camera) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) return Status::Error(path + ": cannot write (" + std::strerror(errno) + ")");
  std::fprintf(file, "# plumb camera file (docs/DATA_FORMATS.md)\n");
  writeReals(file, {{"fx", camera.fx}, {"fy", camera.fy}, {"cx", camera.cx}, {"cy", camera.cy}, {"k1", camera.k1},
                    {"k2", camera.k2}, {"p1", camera.p1}, {"p2", camera.p2}, {"k3", camera.k3}});
  std::fprintf(file, "width %d\nheight %d\n", camera.width, camera.height);
  std::fprintf(file, "depth_factor %.17g\nbaseline %.17g\n", camera.depth_factor, camera.baseline_m);
  // Written even when 0 (global shutter) so a folder exported from a recording replays the same.
  std::fprintf(file, "rolling_shutter_readout %.17g\n", camera.rolling_shutter_readout_s);
  if (camera.depth_camera) {
    const DepthCamera& d = *camera.depth_camera;
    std::fprintf(file, "# depth camera, not registered to colour: P_colour = R(q) P_depth + t (metres)\n");
    writeReals(file, {{"depth_fx", d.fx}, {"depth_fy", d.fy}, {"depth_cx", d.cx}, {"depth_cy", d.cy},
                      {"depth_k1", d.k1}, {"depth_k2", d.k2}, {"depth_p1", d.p1}, {"depth_p2", d.p2},
                      {"depth_k3", d.k3}});
    std::fprintf(file, "depth_width %d\ndepth_height %d\n", d.width, d.height);
    writeReals(file, {{"depth_to_colour_qx", d.qx}, {"depth_to_colour_qy", d.qy}, {"depth_to_colour_qz", d.qz},
                      {"depth_to_colour_qw", d.qw}, {"depth_to_colour_tx", d.tx}, {"depth_to_colour_ty", d.ty},
                      {"depth_to_colour_tz", d.tz}});
  }
  const bool write_failed = std::ferror(file) != 0;
  if (std::fclose(file) != 0 || write_failed) return Status::Error(path + ": write failed");
  return Status::Ok();
}

}  // namespace plumb

#include "drivers/open/open_source.h"

#include <cctype>

#include "drivers/common/text_lines.h"
#include "drivers/dataset/camera_presets.h"
#include "drivers/dataset/tum_dataset.h"
#include "drivers/open/sensor_source_specs.h"
#include "drivers/synth/synth_spec.h"
#include "platform/input_file.h"

namespace plumb {
namespace {

// The benchmark's folder names say which sensor recorded them (rgbd_dataset_freiburg1_desk,
// tum_fr1_rpy, living_room_traj0_frei_png, ...). Empty when the name does not tell.
std::string cameraPresetFromFolderName(const std::string& folder) {
  std::string name = folder;
  while (!name.empty() && name.back() == '/') name.pop_back();
  name = name.substr(name.find_last_of('/') == std::string::npos ? 0 : name.find_last_of('/') + 1);
  for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const struct {
    const char* pattern;
    const char* preset;
  } rules[] = {{"freiburg1", "tum1"}, {"fr1", "tum1"},        {"freiburg2", "tum2"}, {"fr2", "tum2"},
               {"freiburg3", "tum3"}, {"fr3", "tum3"},        {"icl", "icl"},        {"living_room", "icl"},
               {"livingroom", "icl"}, {"office_room", "icl"}, {"frei_png", "icl"}};
  for (const auto& rule : rules)
    if (name.find(rule.pattern) != std::string::npos) return rule.preset;
  return "";
}

// synth:PRESET[:SEED[:FRAMES]]; a synthetic scene always uses its own exact camera.
Status openSynthetic(const std::string& spec, const std::string& camera_spec,
                     std::unique_ptr<FrameSource>* out) {
  if (!camera_spec.empty())
    return Status::Error(spec + ": a synthetic scene has its own camera; drop --camera " + camera_spec);
  std::unique_ptr<SyntheticSource> source;
  PLUMB_RETURN_IF_ERROR(openSynthSpec(spec, false, &source));
  *out = std::move(source);
  return Status::Ok();
}

}  // namespace

Status openFrameSource(const std::string& spec, const std::string& camera_spec,
                       std::unique_ptr<FrameSource>* out) {
  return openFrameSource(spec, camera_spec, SourceOpenOptions{}, out);
}

Status openFrameSource(const std::string& spec, const std::string& camera_spec, const SourceOpenOptions& options,
                       std::unique_ptr<FrameSource>* out) {
  if (spec.empty()) return Status::Error("empty source specification");
  if (isSynthSpec(spec)) return openSynthetic(spec, camera_spec, out);
  if (isSensorOrRecordingSpec(spec)) return openSensorOrRecordingSource(spec, camera_spec, out);

  // A dataset folder: an explicit camera wins, then the folder's camera.txt, then the sensor its
  // name tells; otherwise refuse rather than guess intrinsics (a wrong camera fails silently).
  std::string camera_choice = camera_spec;
  if (camera_choice.empty()) {
    const std::string folder_camera = spec + "/camera.txt";
    // Present in any form (a FIFO too: the camera reader then refuses it) wins over the name.
    camera_choice = pathKind(folder_camera) != PathKind::kMissing ? folder_camera : cameraPresetFromFolderName(spec);
  }
  if (camera_choice.empty())
    return Status::Error(spec +
                         ": no camera.txt and the folder name does not name the sensor; "
                         "pass a camera (tum1 tum2 tum3 icl or a camera file)");
  PinholeCamera camera;
  PLUMB_RETURN_IF_ERROR(cameraFromSpec(camera_choice, &camera));
  std::unique_ptr<TumDatasetSource> source;
  PLUMB_RETURN_IF_ERROR(TumDatasetSource::open(spec, camera, &source, options.max_frames));
  *out = std::move(source);
  return Status::Ok();
}

}  // namespace plumb

#pragma once
// openFrameSource: turns a command-line source specification into a FrameSource.
//   DIR                          TUM RGB-D / ICL-NUIM (TUM format) folder
//   synth:PRESET[:SEED[:FRAMES]] synthetic scene rendered on the fly (drivers/synth)
//   recordings, .oni files, openni2:, v4l2: see drivers/recording/sensor_source_specs.h
// camera_spec is a preset (tum1 tum2 tum3 icl) or a camera file. When empty: the folder's own
// camera.txt if present, else the preset its name implies (freiburg1/fr1 -> tum1, fr2 -> tum2,
// fr3 -> tum3, icl/living_room/office_room/frei_png -> icl), else an error asking for a camera.
// Synthetic scenes bring their own exact camera (a camera_spec is then an error).
#include <cstddef>
#include <memory>
#include <string>

#include "drivers/common/frame_source.h"
#include "platform/status.h"

namespace plumb {

Status openFrameSource(const std::string& spec, const std::string& camera_spec,
                       std::unique_ptr<FrameSource>* out);

struct SourceOpenOptions {
  // > 0: the caller reads at most this many frames; a dataset folder then reads and checks only
  // that many lines of associations.txt (a run of 5 frames over a million-line list stays small
  // and fast). 0: all.
  std::size_t max_frames = 0;
};
Status openFrameSource(const std::string& spec, const std::string& camera_spec, const SourceOpenOptions& options,
                       std::unique_ptr<FrameSource>* out);

}  // namespace plumb

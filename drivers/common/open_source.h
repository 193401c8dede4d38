#pragma once
// openFrameSource: turns a command-line source specification into a FrameSource.
//   DIR                          TUM RGB-D / ICL-NUIM (TUM format) folder
//   synth:PRESET[:SEED[:FRAMES]] synthetic scene rendered on the fly (drivers/synth)
// camera_spec is a preset (tum1 tum2 tum3 icl) or a camera file; when empty, a folder's own
// camera.txt is used if present, else tum1 for TUM folders; synthetic scenes bring their camera.
#include <memory>
#include <string>

#include "drivers/common/frame_source.h"
#include "platform/status.h"

namespace plumb {

Status openFrameSource(const std::string& spec, const std::string& camera_spec,
                       std::unique_ptr<FrameSource>* out);

}  // namespace plumb

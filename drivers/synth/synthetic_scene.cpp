// SyntheticScene: presets, validation, and the glue between room, path, renderer and sensor model.
#include "drivers/synth/synthetic_scene.h"

#include <cmath>

#include "drivers/synth/camera_path.h"
#include "drivers/synth/corridor_layout.h"
#include "drivers/synth/corridor_path.h"
#include "drivers/synth/depth_camera_view.h"
#include "drivers/synth/frame_renderer.h"
#include "drivers/synth/office_layout.h"
#include "drivers/synth/office_path.h"
#include "drivers/synth/room_layout.h"
#include "drivers/synth/sensor_model.h"
#include "drivers/synth/synth_random.h"

namespace plumb {

namespace {

constexpr double kFirstTimestamp = 1000.0;

// What a preset changes. The room presets share one layout per seed; "loop" circles nearer the
// walls, looking at them, twice; "repeated" is a different building (a corridor, layout below).
struct Preset {
  const char* name;
  bool textured;
  double rotation_scale;
  int laps = 1;                   // laps of the closed path per period (period = laps x loop_period_s)
  double lap_variation_m = 0.0;   // how far lap 2 strays from lap 1
  double radius_x_m = 1.8, radius_y_m = 1.3;
  synth::PathGaze gaze = synth::PathGaze::kAcrossRoom;
  double wall_gaze_lead_rad = 0.0;  // kAtWall: gaze turned this far towards the travel direction
  bool corridor = false;          // the repeated-texture corridor instead of the room
  int default_frames = 300;       // what `synth:NAME` renders when no frame count is given
  // The open-plan office with repeated furniture (office_layout.h) instead of the room; the path
  // circles its centre, or with office_pass walks once along its workstations (office_path.h).
  bool office = false;
  bool office_pass = false;
};
constexpr Preset kPresets[] = {
    {"textured", true, 1.0},
    {"low_texture", false, 1.0},
    {"fast_rotation", true, 2.0},
    // Tuned so that the noisy odometry drifts 2-3 cm ATE over the two laps (docs/SYNTHETIC.md).
    {"loop", true, 1.0, 2, 0.05, 2.3, 1.7, synth::PathGaze::kAtWall, 0.2, false, 1200},
    {"repeated", true, 1.0, 1, 0.0, 0.0, 0.0, synth::PathGaze::kAcrossRoom, 0.0, true, 900},
    // The office (docs/SYNTHETIC.md): two laps around the meeting table looking across the room at
    // the repeated furniture, lap 2 beside lap 1 (revisits); and one pass along the identical
    // workstations (no revisit).
    {"office_loop", true, 1.0, 2, 0.05, 3.0, 2.0, synth::PathGaze::kAcrossRoom, 0.0, false, 1200, true, false},
    {"office_pass", true, 1.0, 1, 0.0, 0.0, 0.0, synth::PathGaze::kAcrossRoom, 0.0, false, 800, true, true},
};

const Preset* findPreset(const std::string& name) {
  for (const Preset& p : kPresets)
    if (name == p.name) return &p;
  return nullptr;
}

}  // namespace

int presetDefaultFrames(const std::string& preset) {
  const Preset* p = findPreset(preset);
  return p ? p->default_frames : 0;
}

Status validate(const SynthOptions& o) {
  if (!findPreset(o.preset))
    return Status::Error("synth: unknown preset '" + o.preset +
                         "' (use textured, low_texture, fast_rotation, loop, repeated, office_loop or office_pass)");
  if (o.frames <= 0) return Status::Error("synth: frames must be positive (got " + std::to_string(o.frames) + ")");
  if (!std::isfinite(o.fps) || o.fps <= 0) return Status::Error("synth: fps must be a positive number");
  if (!std::isfinite(o.loop_period_s) || o.loop_period_s <= 0)
    return Status::Error("synth: loop_period_s must be a positive number");
  if (!std::isfinite(o.pixel_noise_sigma) || o.pixel_noise_sigma < 0)
    return Status::Error("synth: pixel noise sigma must be >= 0");
  if (!std::isfinite(o.depth_noise_k) || o.depth_noise_k < 0)
    return Status::Error("synth: depth noise k must be >= 0");
  const double max_representable_m = 65535.0 / synthCamera().depth_factor;
  if (!(o.min_depth_m >= 0 && o.min_depth_m < o.max_depth_m && o.max_depth_m <= max_representable_m))
    return Status::Error("synth: need 0 <= min_depth_m < max_depth_m <= " + std::to_string(max_representable_m));
  return synth::validateDepthCamera(o);
}

PinholeCamera synthCamera() {
  PinholeCamera camera;
  camera.fx = 525.0;
  camera.fy = 525.0;
  camera.cx = 319.5;
  camera.cy = 239.5;
  camera.width = 640;
  camera.height = 480;
  camera.depth_factor = 5000.0;
  return camera;
}

class SyntheticSceneImpl {
 public:
  explicit SyntheticSceneImpl(const SynthOptions& options)
      : options_(options),
        camera_(synthCamera()),
        corridor_(findPreset(options.preset)->corridor),
        office_pass_(findPreset(options.preset)->office_pass),
        model_(buildModel(options)),
        path_(pathOptions(options)),
        corridor_path_(synth::CorridorPathOptions{options.seed}),
        office_path_(synth::OfficePathOptions{options.seed}),
        renderer_(model_, camera_) {
    if (options.depth_camera) {
      camera_.depth_camera = options.depth_camera;
      depth_view_ = std::make_unique<synth::DepthCameraView>(model_, *options.depth_camera);
    }
    sensor_.pixel_noise_sigma = options.pixel_noise_sigma;
    sensor_.depth_noise = options.depth_noise;
    sensor_.depth_noise_k = options.depth_noise_k;
    sensor_.depth_edge_holes = options.depth_edge_holes;
    sensor_.min_depth_m = options.min_depth_m;
    sensor_.max_depth_m = options.max_depth_m;
    sensor_.depth_factor = camera_.depth_factor;
    noise_seed_ = synth::mix64(options.seed ^ 0x4e6f697365ULL);
  }

  static synth::SceneModel buildModel(const SynthOptions& options) {
    if (findPreset(options.preset)->corridor) return synth::buildCorridor(corridorOptions(options));
    if (findPreset(options.preset)->office) return synth::buildOffice(synth::OfficeLayoutOptions{options.seed});
    return synth::buildRoom(layoutOptions(options));
  }
  static synth::RoomLayoutOptions layoutOptions(const SynthOptions& options) {
    synth::RoomLayoutOptions layout;
    layout.textured = findPreset(options.preset)->textured;
    layout.seed = options.seed;
    return layout;
  }
  static synth::CorridorLayoutOptions corridorOptions(const SynthOptions& options) {
    synth::CorridorLayoutOptions layout;
    layout.seed = options.seed;
    return layout;
  }
  static synth::CameraPathOptions pathOptions(const SynthOptions& options) {
    synth::CameraPathOptions path;
    path.seed = options.seed;
    const Preset& preset = *findPreset(options.preset);
    path.period_s = options.loop_period_s * preset.laps;
    path.rotation_scale = preset.rotation_scale;
    path.laps = preset.laps;
    path.lap_variation_m = preset.lap_variation_m;
    path.radius_x_m = preset.radius_x_m;
    path.radius_y_m = preset.radius_y_m;
    path.gaze = preset.gaze;
    path.wall_gaze_lead_rad = preset.wall_gaze_lead_rad;
    if (preset.office) path.centre_world = Eigen::Vector3d(synth::kOfficeWidth / 2, 3.6, 0.0);
    return path;
  }

  Eigen::Isometry3d T_world_cam(double t_s) const {
    if (office_pass_) return office_path_.T_world_cam(t_s);
    return corridor_ ? corridor_path_.T_world_cam(t_s) : path_.T_world_cam(t_s);
  }

  SynthOptions options_;
  PinholeCamera camera_;
  bool corridor_;
  bool office_pass_;
  synth::SceneModel model_;
  synth::CameraPath path_;
  synth::CorridorPath corridor_path_;
  synth::OfficePassPath office_path_;
  synth::FrameRenderer renderer_;  // scratch buffers: why render() is not reentrant
  std::unique_ptr<synth::DepthCameraView> depth_view_;  // SynthOptions::depth_camera only
  synth::SensorModelOptions sensor_;
  uint64_t noise_seed_ = 0;
};

SyntheticScene::SyntheticScene(std::unique_ptr<SyntheticSceneImpl> impl) : impl_(std::move(impl)) {}
SyntheticScene::~SyntheticScene() = default;

Status SyntheticScene::create(const SynthOptions& options, std::unique_ptr<SyntheticScene>* out) {
  PLUMB_RETURN_IF_ERROR(validate(options));
  out->reset(new SyntheticScene(std::make_unique<SyntheticSceneImpl>(options)));
  return Status::Ok();
}

const SynthOptions& SyntheticScene::options() const { return impl_->options_; }
const PinholeCamera& SyntheticScene::camera() const { return impl_->camera_; }
int SyntheticScene::numFrames() const { return impl_->options_.frames; }

double SyntheticScene::timestamp(int i) const { return kFirstTimestamp + i / impl_->options_.fps; }

Eigen::Isometry3d SyntheticScene::T_world_cam(int i) const {
  return impl_->T_world_cam(i / impl_->options_.fps);
}

Status SyntheticScene::render(int i, RgbdImage& out) const {
  if (i < 0) return Status::Error("synth: frame index must be >= 0 (got " + std::to_string(i) + ")");
  SyntheticSceneImpl& impl = *impl_;
  impl.renderer_.render(T_world_cam(i));
  // Unregistered depth: the depth camera's own view, in its own image (depth_camera_view.h).
  if (impl.depth_view_) impl.depth_view_->render(T_world_cam(i));
  const cv::Mat& depth_m = impl.depth_view_ ? impl.depth_view_->depth() : impl.renderer_.depth();
  // Colour and depth are quantised independently (separate noise streams, separate outputs): on
  // a frame that painted faces (the renderer used its helper thread), one there, one here.
  auto colour = [&] { synth::quantiseColour(impl.renderer_.colour(), impl.sensor_, impl.noise_seed_, i, out.bgr); };
  auto depth = [&] { synth::quantiseDepth(depth_m, impl.sensor_, impl.noise_seed_, i, out.depth_raw); };
  if (impl.renderer_.paintedFaces()) {
    impl.renderer_.helper().runBoth(colour, depth);
  } else {
    colour();
    depth();
  }
  out.sequence = static_cast<uint64_t>(i);
  out.timestamp_s = timestamp(i);
  out.depth_timestamp_s = out.timestamp_s;
  out.depth_factor = impl.camera_.depth_factor;
  return Status::Ok();
}

}  // namespace plumb

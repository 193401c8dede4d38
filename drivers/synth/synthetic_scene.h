#pragma once
// Seeded synthetic RGB-D scenes: a deterministic renderer of an indoor room (walls, floor,
// ceiling, furniture, shelves, door and window frames) seen by a hand-held-like camera with exact
// ground truth. The backbone of the tests and the default demo.
//
//   SynthOptions options;                      // preset, seed, frames, noise
//   std::unique_ptr<SyntheticScene> scene;
//   PLUMB_RETURN_IF_ERROR(SyntheticScene::create(options, &scene));
//   RgbdImage frame;                           // buffers allocated on the first render only
//   scene->render(i, frame);                   // deterministic: same options -> same bytes
//   Eigen::Isometry3d T_world_cam = scene->T_world_cam(i);
//
// Conventions: world frame z up (metres, room floor at z = 0); camera optical frame x right,
// y down, z forward (TUM); depth is metres along the optical axis, stored raw as
// round(z * depth_factor), 0 = no reading. See docs/SYNTHETIC.md for the scene, the noise model,
// the trajectory and the determinism guarantees.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "drivers/common/frame_source.h"
#include "sensor/camera.h"
#include "sensor/rgbd_image.h"
#include "platform/status.h"

namespace plumb {

struct SynthOptions {
  // Appearance and motion of the scene:
  //   "textured"      rich procedural texture everywhere (blobs, noise, posters, checkers): many corners
  //   "low_texture"   plain faces in flat, distinct shades: strong straight edges, few corners
  //   "fast_rotation" the textured room with a faster, more rotational hand-held motion (~2.4x
  //                   the peak angular rate; same path)
  //   "loop"          the textured room circled twice near the walls, looking at them: lap 2
  //                   revisits lap 1's views a few cm and degrees apart; the path closes after
  //                   2 x loop_period_s (1200 frames at the defaults). For loop closing.
  //   "repeated"      a 36 m corridor of identical 3 m modules (doors, pictures, textures), walked
  //                   one way: repeated texture and no real loop. For rejecting false loops.
  // The room presets of one seed share the geometry; textured/low_texture/fast_rotation share the
  // trajectory too.
  std::string preset = "textured";
  // Everything random (layout jitter, colours, textures, trajectory phases, noise) derives from it.
  uint64_t seed = 1;
  // Frames rendered. The camera path is a closed loop of `loop_period_s`; longer runs repeat it
  // smoothly (so a 10,000-frame run is many identical laps: no separate `loops` count needed).
  int frames = 300;
  double fps = 30.0;
  // Duration of one lap of the closed camera path ("loop": of each of its two laps; "repeated"
  // walks at a fixed speed and ignores it). One lap is ~9 m of travel, so the default
  // 300 frames (10 s) cover about half a lap: ~4.5 m at ~0.45 m/s, like a hand-held TUM sequence.
  double loop_period_s = 20.0;

  // Sensor model (all off by default: noise-free renders are exact).
  double pixel_noise_sigma = 0.0;   // grey levels, zero-mean Gaussian on each colour channel
  bool depth_noise = false;         // Kinect-like axial noise, sigma_z = depth_noise_k * z^2
  double depth_noise_k = 0.0014;    // 1/m; Khoshelham & Elberink 2012 report ~1.4e-3 z^2 for Kinect v1
  bool depth_edge_holes = false;    // zero depth on the far side of depth discontinuities (1-3 px)
  double max_depth_m = 8.0;         // farther surfaces read 0 (no reading), like the sensor
  double min_depth_m = 0.3;         // nearer surfaces read 0

  // Depth from a separate depth camera, NOT registered to colour (UVC depth cameras: RealSense,
  // Orbbec, a Kinect v1 without registration): depth images are rendered from this camera (its
  // intrinsics and size, at T_world_colour * T_colour_depth; no distortion: the renderer is a
  // pinhole), and the scene's camera() carries it, so plumb registers the depth before use.
  // Colour images and ground truth stay the colour camera's, byte for byte. Empty (default):
  // depth rendered from the colour camera (registered). synthOffsetDepthCamera() is a typical one.
  std::optional<DepthCamera> depth_camera;
};

// A Kinect v1 / RealSense-like depth camera beside the synthetic colour camera (docs/SYNTHETIC.md
// "Unregistered depth"): 640x480, fx = fy = 575, principal point (314, 243), 2.5 cm to the side
// (T_colour_depth translation (0.025, 0.001, -0.002) m) and turned 0.53 degrees.
DepthCamera synthOffsetDepthCamera();
// The same depth camera with half the resolution (320x240, same field of view and pose): a depth
// image smaller than the colour image, as many depth cameras deliver.
DepthCamera synthOffsetDepthCameraQvga();

// The frame count a preset is meant to be run with: 300 (10 s) for the room presets, 1200 (both
// laps) for "loop", 900 (30 s, ~13.5 m of corridor) for "repeated"; 0 for an unknown preset.
// SynthOptions::frames stays 300 unless set; parseSynthSpec (synth_spec.h) uses this when a spec
// gives no count, so `synth:loop` renders both laps.
int presetDefaultFrames(const std::string& preset);

// Empty-OK or a message naming the bad option (unknown preset, frames <= 0, fps <= 0, ...).
Status validate(const SynthOptions& options);

// The (colour) camera of every synthetic scene: 640x480, fx = fy = 525, cx = 319.5, cy = 239.5,
// no distortion, depth_factor 5000 (TUM Freiburg "ROS default" intrinsics). A scene with
// SynthOptions::depth_camera adds it to this camera (SyntheticScene::camera()).
PinholeCamera synthCamera();

class SyntheticSceneImpl;

class SyntheticScene {
 public:
  // Builds the room, its texture recipes and the camera path (~1 ms); a face's texture is painted
  // when a frame first shows it.
  static Status create(const SynthOptions& options, std::unique_ptr<SyntheticScene>* out);
  ~SyntheticScene();

  const SynthOptions& options() const;
  const PinholeCamera& camera() const;
  int numFrames() const;
  // 1000.0 + i / fps seconds (the same value in every file the writer produces).
  double timestamp(int i) const;
  // Exact ground-truth pose of frame i (maps camera-frame points to world). Any i >= 0 is valid
  // (the path is periodic), so callers may sample beyond numFrames().
  Eigen::Isometry3d T_world_cam(int i) const;
  // Renders frame i into `out` (bgr CV_8UC3, depth_raw CV_16UC1, timestamps, depth_factor).
  // Reuses out's buffers when their size and type match, so steady-state rendering does not
  // allocate (once every face in view has been painted). Deterministic: the bytes depend only on
  // the options and i, not on the frames rendered before. Not safe to call
  // concurrently on one scene (it uses the scene's scratch buffers); use one scene per thread.
  Status render(int i, RgbdImage& out) const;

 private:
  explicit SyntheticScene(std::unique_ptr<SyntheticSceneImpl> impl);
  std::unique_ptr<SyntheticSceneImpl> impl_;
};

// A FrameSource that renders frame after frame on the fly (no disk): frames 0..numFrames()-1,
// then kEndOfStream. t_sensor_ns is the host monotonic time of delivery.
class SyntheticSource : public FrameSource {
 public:
  static Status create(const SynthOptions& options, std::unique_ptr<SyntheticSource>* out);

  SourceResult next(RgbdImage& out) override;
  const PinholeCamera& camera() const override;
  std::string describe() const override;  // "synth:<preset>:seed=<seed>"
  const Status& lastError() const override;
  std::size_t frameCount() const override { return std::size_t(scene_->numFrames()); }

  const SyntheticScene& scene() const { return *scene_; }
  int nextIndex() const { return next_index_; }

 private:
  explicit SyntheticSource(std::unique_ptr<SyntheticScene> scene);
  std::unique_ptr<SyntheticScene> scene_;
  int next_index_ = 0;
  Status last_error_;
};

// Writes the scene in TUM layout into out_dir (created if missing):
//   rgb/<t>.png (8-bit BGR), depth/<t>.png (16-bit, depth_factor 5000), rgb.txt, depth.txt,
//   associations.txt (`t rgb/<t>.png t depth/<t>.png`), groundtruth.txt
//   (`timestamp tx ty tz qx qy qz qw`), camera.txt (`key value` lines: fx fy cx cy k1 k2 p1 p2 k3
//   width height depth_factor, `#` comments).
// Timestamps are printed "%.6f" everywhere. Same options -> byte-identical folder.
Status writeSynthDataset(const SynthOptions& options, const std::string& out_dir);

}  // namespace plumb

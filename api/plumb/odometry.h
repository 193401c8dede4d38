#pragma once
// plumb's public API: point + line RGB-D odometry from your own program.
//
//   #include <plumb/odometry.h>
//
//   plumb::api::OdometryConfig config;                 // camera + options, documented defaults
//   config.camera = plumb::api::CameraSpec::named("tum1");   // preset or camera file
//   std::unique_ptr<plumb::api::Odometry> odometry;
//   plumb::api::Status st = plumb::api::Odometry::create(config, &odometry);
//   if (!st.ok) { ...st.message... }
//   for (each frame) {
//     plumb::api::FrameView frame{bgr_data, depth_data, timestamp_s};    // + sizes, strides
//     plumb::api::TrackOutput out;
//     st = odometry->track(frame, &out);   // out.state, out.T_world_cam, out.covariance
//     plumb::api::FinishedPose pose;       // poses refined by local BA, output_delay frames later
//     while (odometry->popFinished(&pose)) { ... }
//   }
//   odometry->finish();                    // then popFinished() the held-back rest
//
// track() steps the same run session as `plumb run` (pipeline/run/run_session.h), lock-step,
// one frame per call: the same frames give the same poses as `plumb run --mode deterministic`.
// After a warm-up of ~30 frames a call allocates no memory.
//
// runSource() is the staged runtime through the same front door: a source spec (a TUM folder,
// synth:textured, a recording, a sensor) in a mode (deterministic, fast, realtime), one callback
// per tracked pose.
//
// This header needs only the C++17 standard library and Eigen; errors are values (Status), no
// exception leaves the library. Linking the library replaces the global operator new/delete with
// versions that count allocations (platform/allocation_counter.h) and otherwise call malloc/free.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace plumb::api {

// An error as a value: ok, or a message that says what is wrong.
struct Status {
  bool ok = true;
  std::string message;
  static Status Ok() { return {}; }
  static Status Error(std::string text) { return {false, std::move(text)}; }
};

// Pinhole intrinsics and Brown-Conrady distortion (OpenCV order), image size, depth scale.
struct CameraValues {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
  int width = 640, height = 480;
  double depth_factor = 5000.0;  // raw depth units per metre (TUM 5000, millimetre images 1000)
  double baseline_m = 0.08;      // virtual stereo baseline of the point observation
  // Rolling shutter: seconds from the first to the last row's exposure (0 = global shutter; the
  // TUM presets: 0.025). The tracker moves features to the middle row's time.
  double rolling_shutter_readout_s = 0.0;
};

// Where the camera comes from: a preset name (tum1 tum2 tum3 icl), a camera file (docs/DATA_FORMATS.md),
// or values.
struct CameraSpec {
  std::string name_or_file;  // used when !use_values
  bool use_values = false;
  CameraValues values;
  static CameraSpec named(std::string preset_or_file) { return {std::move(preset_or_file), false, {}}; }
  static CameraSpec fromValues(const CameraValues& v) { return {"", true, v}; }
};
// The camera a spec names, validated (error names what is wrong).
Status resolveCamera(const CameraSpec& spec, CameraValues* out);

struct OdometryConfig {
  CameraSpec camera = CameraSpec::named("tum1");
  bool lines = true;             // line features for tracking and mapping (false: points only)
  int line_samples = 5;          // line-guidance points per line: 0 or 2..10
  int output_delay_frames = 60;  // finished poses are held back this many frames for local BA
  bool loop_closing = true;      // loop closing (docs/LOOP.md), as `plumb run`; false = `--no-loops`
};

enum class PixelFormat { kBgr, kRgb };

// One RGB-D frame, borrowed for the duration of track(). Colour: 8-bit, 3 channels, HxW of the
// camera; depth: 16-bit raw units (metres = value / depth_factor, 0 = no reading), same size.
// Strides in bytes (0 = tightly packed rows).
struct FrameView {
  const uint8_t* color = nullptr;
  const uint16_t* depth = nullptr;
  double timestamp_s = 0;
  int width = 0, height = 0;
  std::size_t color_stride = 0, depth_stride = 0;
  PixelFormat format = PixelFormat::kBgr;
};

enum class TrackingState { kNotInitialized, kOk, kWeak, kLost };
const char* toString(TrackingState state);  // "not_initialized" "ok" "weak" "lost"

// The frame's pose as tracking has it (before local BA refines anything).
struct TrackOutput {
  uint64_t sequence = 0;  // 0, 1, 2, ... per track() call
  double timestamp_s = 0;
  TrackingState state = TrackingState::kNotInitialized;
  bool has_pose = false;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();  // camera to world (TUM)
  // 6x6 covariance of the left perturbation delta = [rho; phi] of T_cam_world
  // (T_cam_world <- exp(delta) T_cam_world, solver/se3.h), when tracking computed one.
  bool covariance_valid = false;
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool keyframe = false, relocalized = false, new_map = false;
  int point_inliers = 0, line_inliers = 0;
};

// A frame whose output pose is final (the trajectory `plumb run --out` writes), oldest first.
struct FinishedPose {
  uint64_t sequence = 0;
  double timestamp_s = 0;
  bool valid = false;  // false: the frame had no pose (written as `# <t> lost`)
  bool dropped = false;  // realtime runSource(): never processed (`# <t> dropped`); valid is false
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
};

struct Counters {
  uint64_t frames = 0;
  uint64_t frames_ok = 0, frames_weak = 0, frames_lost = 0;
  uint64_t keyframes = 0;
  uint64_t relocalizations = 0;
  uint64_t map_segments = 0;  // maps started (1 = never restarted)
  uint64_t extraction_failures = 0;
};

class Odometry {
 public:
  static Status create(const OdometryConfig& config, std::unique_ptr<Odometry>* out);
  ~Odometry();
  Odometry(const Odometry&) = delete;
  Odometry& operator=(const Odometry&) = delete;

  const CameraValues& camera() const;
  // One frame through extract, track and map. Wrong sizes or null pointers: an error, nothing runs.
  Status track(const FrameView& frame, TrackOutput* out);
  // The next finished pose, oldest first; false when none is ready.
  bool popFinished(FinishedPose* out);
  // End of input: every held-back pose becomes finished (popFinished). track() is refused after.
  Status finish();
  Counters counters() const;

  struct Impl;

 private:
  explicit Odometry(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// ---- The staged runtime (pipeline/run/odometry_run.h) through the same front door.

struct RunConfig {
  std::string source;       // TUM folder, synth:PRESET[:SEED[:FRAMES]], recording, sensor spec
  std::string camera;       // preset or camera file ('' = the source's own)
  std::string mode = "deterministic";  // deterministic | fast | realtime
  bool lines = true;
  int line_samples = 5;
  int output_delay_frames = 60;
  long max_frames = -1;     // -1: every frame
};
struct RunSummary {
  Counters counters;
  uint64_t frames_dropped = 0;
  double frames_per_second = 0;
};
// on_pose: every tracked pose, on the track stage's thread, in frame order (must not block).
// on_finished (may be empty): every finished pose, in frame order.
Status runSource(const RunConfig& config, const std::function<void(const TrackOutput&)>& on_pose,
                 const std::function<void(const FinishedPose&)>& on_finished, RunSummary* summary);

// ---- Frames from plumb's own sources (for examples, notebooks and tests).

class FrameReader {
 public:
  // spec: TUM folder or synth:PRESET[:SEED[:FRAMES]]; camera: '' or a preset/file (folders only).
  static Status open(const std::string& spec, const std::string& camera, std::unique_ptr<FrameReader>* out);
  ~FrameReader();
  const CameraValues& camera() const;
  std::size_t frameCount() const;  // 0 when unknown
  // The next frame into caller buffers, resized as needed (BGR, HxWx3 bytes; depth HxW raw).
  // *got = false at the end of the input.
  Status next(std::vector<uint8_t>* bgr, std::vector<uint16_t>* depth, double* timestamp_s, bool* got);
  // Exact camera trajectory (synthetic scenes only; empty otherwise) of the first `frames` frames.
  std::vector<FinishedPose> groundTruth(long frames) const;

  struct Impl;

 private:
  explicit FrameReader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// ---- Trajectories and their evaluation, exactly as `plumb eval` computes them.

// TUM trajectory file (`t tx ty tz qx qy qz qw`); lost markers kept as valid = false.
Status readTrajectory(const std::string& path, std::vector<FinishedPose>* out);
// Same writer as `plumb run --out`: byte-identical files for the same poses.
Status writeTrajectory(const std::string& path, const std::vector<FinishedPose>& poses);

struct ErrorStats {
  double rmse = 0, mean = 0, median = 0, min = 0, max = 0;
};
struct Evaluation {
  bool ate_valid = false, rpe_valid = false;
  std::size_t ate_pairs = 0, rpe_pairs = 0;
  ErrorStats ate_m;               // absolute trajectory error after rigid alignment
  ErrorStats rpe_m_per_s;         // relative pose error over 1 s, translation
  ErrorStats rpe_deg_per_s;       // and rotation
  std::string ate_error, rpe_error;  // why one is missing
};
// ATE (TUM evaluate_ate.py conventions) and RPE (evaluate_rpe.py, delta 1 s).
Evaluation evaluate(const std::vector<FinishedPose>& ground_truth, const std::vector<FinishedPose>& estimate);

}  // namespace plumb::api

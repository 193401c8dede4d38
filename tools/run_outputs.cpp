#include "tools/run_outputs.h"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <memory>

#include "platform/monotonic_time.h"
#include "platform/process_memory.h"

#include "drivers/common/source_capture.h"
#include "pipeline/odometry/odometry_trajectory.h"
#include "pipeline/odometry/published_covariance.h"

namespace plumb::tools {

RunOutputs::RunOutputs(const RunOutputOptions& options) : options_(options), statistics_(options.rss_every) {
  // Reserved once so keeping poses for the ATE costs no allocation per frame.
  if (options_.keep_trajectory) trajectory_.reserve(std::min(options_.expected_frames, kMaxReservedPoses));
}

namespace {

// What --out-optimized needs of a finished frame, streamed to the temporary file.
struct StreamedFrame {
  double timestamp = 0;
  uint8_t valid = 0, dropped = 0;
  uint32_t reference_id = 0;
  double T_ref_cam[12] = {};    // 3x4, row major
  double T_world_cam[12] = {};  // real-time pose (fallback)
  uint64_t loop_epoch = 0;      // FinishedFrame::loop_epoch
};

void toRows(const Eigen::Isometry3d& T, double* out) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) out[r * 4 + c] = T.matrix()(r, c);
  }
}

Eigen::Isometry3d fromRows(const double* in) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) T.matrix()(r, c) = in[r * 4 + c];
  }
  return T;
}

}  // namespace

RunOutputs::~RunOutputs() {
  if (frames_stream_ != nullptr) std::fclose(frames_stream_);
}

Status RunOutputs::begin(const OdometrySystem&) {
  if (!options_.optimized_path.empty()) {
    frames_stream_ = std::tmpfile();
    if (frames_stream_ == nullptr) return Status::Error("--out-optimized: cannot create a temporary file");
  }
  if (!options_.trajectory_path.empty()) PLUMB_RETURN_IF_ERROR(trajectory_writer_.open(options_.trajectory_path));
  if (!options_.covariance_path.empty()) PLUMB_RETURN_IF_ERROR(covariance_writer_.open(options_.covariance_path));
  if (!options_.track_covariance_path.empty()) {
    PLUMB_RETURN_IF_ERROR(track_covariance_writer_.open(options_.track_covariance_path, CovarianceFileKind::kTracked));
  }
  if (!options_.mavlink.endpoint.empty()) {
    mavlink_ = std::make_unique<MavlinkOdometrySink>();
    PLUMB_RETURN_IF_ERROR(mavlink_->open(options_.mavlink).withContext("--mavlink"));
  }
  opened_ = true;
  return Status::Ok();
}

void RunOutputs::onPose(const FrameOutput& out) {
  if (options_.report_every > 0) reportBlock(out);
  if (!mavlink_) return;
  OdometrySample sample;
  sample.timestamp_s = out.timestamp_s;
  sample.has_pose = out.has_pose;
  sample.T_world_cam = out.T_world_cam;
  // Quality from the tracking state: ok (enough inliers) 100, weak (pose kept, few inliers) 50.
  sample.tracking_quality = out.state == TrackingState::kOk ? 100 : out.state == TrackingState::kWeak ? 50 : 0;
  sample.has_covariance = out.has_pose && out.track.covariance_valid;
  sample.covariance = out.track.covariance;
  sample.has_local_covariance = out.has_pose && out.track.covariance_local_valid;
  sample.local_covariance = out.track.covariance_local;
  // The estimate jumps at a new map segment, a relocalization and a loop correction: the
  // autopilot must know (docs/LOOP.md "What the robot receives").
  sample.reset = out.new_map || out.relocalized || out.loop_corrected;
  sample.has_previous_in_map = out.has_pose && out.track.has_previous;
  sample.previous_timestamp_s = out.track.previous_timestamp_s;
  sample.T_world_previous_cam = out.track.T_world_previous;
  mavlink_->publish(sample);
}

Status RunOutputs::close(bool keep) {
  endProgress();
  if (!opened_) return Status::Ok();
  if (!keep) {
    trajectory_writer_.abandon();
    covariance_writer_.abandon();
    track_covariance_writer_.abandon();
    if (frames_stream_ != nullptr) std::fclose(frames_stream_);
    frames_stream_ = nullptr;
    return Status::Ok();
  }
  if (!options_.trajectory_path.empty()) PLUMB_RETURN_IF_ERROR(trajectory_writer_.close());
  if (!options_.covariance_path.empty()) PLUMB_RETURN_IF_ERROR(covariance_writer_.close());
  if (!options_.track_covariance_path.empty()) PLUMB_RETURN_IF_ERROR(track_covariance_writer_.close());
  return Status::Ok();
}

void RunOutputs::endProgress() {
  if (!progress_line_open_) return;
  std::fputc('\n', stderr);
  progress_line_open_ = false;
}

void RunOutputs::progressLine(uint64_t frame, const FrameOutput& out) {
  const int64_t now = monotonicNowNs();
  if (progress_start_ns_ == 0) progress_start_ns_ = now;
  if (options_.progress_on_terminal) {
    if (now - progress_last_ns_ < 250'000'000 && frame != options_.expected_frames) return;
  } else if (frame % 100 != 0) {
    return;
  }
  progress_last_ns_ = now;
  const double seconds = double(now - progress_start_ns_) * 1e-9;
  const double fps = seconds > 0 ? double(frame) / seconds : 0.0;
  char count[64], eta[48] = "";
  const std::size_t total = options_.expected_frames;
  if (total >= frame && total > 0) {
    std::snprintf(count, sizeof count, "frame %" PRIu64 "/%zu (%.0f%%)", frame, total, 100.0 * double(frame) / double(total));
    if (fps > 0) {
      const long long left = std::llround(double(total - frame) / fps);
      std::snprintf(eta, sizeof eta, ", ETA %lld:%02lld", left / 60, left % 60);
    }
  } else {
    std::snprintf(count, sizeof count, "frame %" PRIu64, frame);
  }
  std::fprintf(stderr, "%s%s, %.1f frames/s%s: %s, keyframes %" PRIu64 ", without pose %" PRIu64 "%s",
               options_.progress_on_terminal ? "\r" : "", count, fps, eta, toString(out.state), keyframes_, lost_,
               options_.progress_on_terminal ? "\x1b[K" : "\n");
  progress_line_open_ = options_.progress_on_terminal;
}

void RunOutputs::reportBlock(const FrameOutput& out) {
  block_latency_.add(monotonicNowNs() - out.t_sensor_ns);
  if (++block_frames_ < uint64_t(options_.report_every)) return;
  long peak_kib = 0, current_kib = 0;
  readRss(&peak_kib, &current_kib);
  const uint64_t dropped = dropped_total_.load(std::memory_order_relaxed);
  std::printf("block %" PRIu64 ": frames %" PRIu64 ", sensor-to-pose p50 %.2f p99 %.2f max %.2f ms, dropped %" PRIu64
              ", rss %ld KiB (peak %ld KiB)\n",
              ++blocks_, block_frames_, double(block_latency_.percentileNs(0.5)) * 1e-6,
              double(block_latency_.percentileNs(0.99)) * 1e-6, double(block_latency_.maxNs()) * 1e-6,
              dropped - dropped_at_block_start_, current_kib, peak_kib);
  std::fflush(stdout);
  dropped_at_block_start_ = dropped;
  block_latency_.clear();
  block_frames_ = 0;
}

Status RunOutputs::onFrame(const FrameOutput& out) {
  statistics_.add(out);
  if (out.dropped) {
    dropped_total_.fetch_add(1, std::memory_order_relaxed);
    return Status::Ok();
  }
  keyframes_ += out.keyframe;
  lost_ += !out.has_pose;
  if (!options_.track_covariance_path.empty() && out.has_pose) {
    PLUMB_RETURN_IF_ERROR(track_covariance_writer_.append(toStampedTrackedCovariance(out)));
  }
  const uint64_t frame = statistics_.frames();
  if (options_.trace) {
    const Eigen::Vector3d t = out.T_world_cam.translation();
    std::fprintf(stderr, "%" PRIu64 " %s fm %d lm %d pi %d li %d lmi %d kf %d np %d nl %d reloc %d fb %d t %.3f %.3f %.3f\n",
                 frame, toString(out.state), out.track.frame_matches, out.track.local_map_matches,
                 out.track.point_inliers, out.track.line_inliers, out.track.landmark_inliers, out.keyframe,
                 out.insert.new_points, out.insert.new_lines, out.relocalized, out.track.used_motion_fallback,
                 t.x(), t.y(), t.z());
  }
  if (options_.progress) progressLine(frame, out);
  return Status::Ok();
}

Status RunOutputs::onFinishedFrame(const FinishedFrame& f) {
  const StampedPose pose = toStampedPose(f);
  if (options_.keep_trajectory) trajectory_.push_back(pose);
  if (frames_stream_ != nullptr) {
    StreamedFrame r;
    r.timestamp = f.timestamp_s;
    r.valid = f.valid;
    r.dropped = f.dropped;
    r.reference_id = f.reference_id;
    toRows(f.T_ref_cam, r.T_ref_cam);
    toRows(f.T_world_cam, r.T_world_cam);
    r.loop_epoch = f.loop_epoch;
    if (std::fwrite(&r, sizeof(r), 1, frames_stream_) != 1) return Status::Error("--out-optimized: temporary file write failed");
  }
  if (!options_.trajectory_path.empty()) return trajectory_writer_.append(pose);
  return Status::Ok();
}

Status RunOutputs::writeOptimized(const LoopRunResult& loop) {
  if (frames_stream_ == nullptr) return Status::Ok();
  if (std::fflush(frames_stream_) != 0 || std::fseek(frames_stream_, 0, SEEK_SET) != 0) {
    return Status::Error("--out-optimized: temporary file unreadable");
  }
  TumTrajectoryWriter writer;
  PLUMB_RETURN_IF_ERROR(writer.open(options_.optimized_path));
  if (options_.keep_trajectory) optimized_.reserve(trajectory_.size());
  StreamedFrame r;
  while (std::fread(&r, sizeof(r), 1, frames_stream_) == 1) {
    StampedPose pose;
    pose.timestamp = r.timestamp;
    pose.valid = r.valid != 0;
    pose.dropped = r.dropped != 0;
    pose.T_world_cam = fromRows(r.T_world_cam);
    FinishedFrame frame;
    frame.valid = pose.valid;
    frame.reference_id = r.reference_id;
    frame.T_ref_cam = fromRows(r.T_ref_cam);
    frame.T_world_cam = pose.T_world_cam;
    frame.loop_epoch = r.loop_epoch;
    if (pose.valid && !loop.optimisedPose(frame, &pose.T_world_cam)) ++optimized_without_keyframe_;
    if (options_.keep_trajectory) optimized_.push_back(pose);
    PLUMB_RETURN_IF_ERROR(writer.append(pose));
  }
  std::fclose(frames_stream_);
  frames_stream_ = nullptr;
  return writer.close();
}

Status RunOutputs::onRetiredKeyframe(const RetiredKeyframe& kf) {
  if (options_.covariance_path.empty()) return Status::Ok();
  return covariance_writer_.append(toStampedCovariance(kf));
}

Status runToOutputs(FrameSource& source, const SystemOptions& system_options, const OdometryRunOptions& run_options,
                    RunOutputs& outputs, RunRecord* record, OdometrySink* sink) {
  SourceCapture capture(source, run_options.stop);
  const Status status = runOdometry(capture, system_options, sink != nullptr ? *sink : outputs, run_options, &record->run);
  // The outputs hold what was computed whatever ended the run, but a run that produced no frame
  // (it failed or was stopped before its first one) replaces no file: an older trajectory of that
  // name is worth more than an empty one.
  record->outputs_kept = record->run.frames + record->run.frames_dropped > 0;
  record->outputs_status = outputs.close(record->outputs_kept);
  if (record->outputs_kept && record->outputs_status.ok()) record->outputs_status = outputs.writeOptimized(record->run.loop);
  record->odometry = record->run.odometry;
  record->mapper = record->run.mapper;
  record->mapper_waits = record->run.mapper_waits;
  return status.ok() ? record->outputs_status : status;
}

}  // namespace plumb::tools

#include "pipeline/run/odometry_run.h"

#include <algorithm>
#include <memory>

#include "pipeline/run/run_session.h"

namespace plumb {

Status validate(const OdometryRunOptions& options) {
  const runtime::RunOptions& s = options.schedule;
  if (s.slot_count < 1 || s.slot_count > 64) return Status::Error("slots must be within 1..64");
  if (s.realtime_priority < 0 || s.realtime_priority > 99) return Status::Error("realtime priority must be within 0..99");
  if (options.max_frames < -1 || options.max_frames == 0) {
    return Status::Error("max_frames must be a positive count (or -1: every frame)");
  }
  if (options.max_frames_ahead_of_mapper < -1 || options.max_frames_ahead_of_mapper > 64) {
    return Status::Error("max_frames_ahead_of_mapper must be within 0..64 (or -1: by mode)");
  }
  if (options.save_map != nullptr && !options.loop_closing) {
    return Status::Error("saving a map needs loop closing (the map is the loop closer's keyframe graph)");
  }
  if (options.load_map != nullptr && options.load_map->keyframes.empty()) {
    return Status::Error("the loaded map holds no keyframes: nothing to relocalize against");
  }
  return Status::Ok();
}

bool LoopRunResult::keyframeFinalPose(uint32_t id, uint64_t epoch, Eigen::Isometry3d* T_world_graph,
                                      Eigen::Isometry3d* T_world_final) const {
  const auto it = std::lower_bound(keyframes.begin(), keyframes.end(), id,
                                   [](const std::pair<uint32_t, Eigen::Isometry3d>& k, uint32_t v) { return k.first < v; });
  if (it == keyframes.end() || it->first != id) return false;
  const FinalPose& f = keyframe_finals[std::size_t(it - keyframes.begin())];
  if (!f.has_final || f.epoch < epoch || f.epoch > epoch_corrections.size()) return false;
  // Corrections applied after the frame was queued and before the keyframe retired moved the
  // local map, that keyframe with it, by C (a new map segment retires every keyframe first, so
  // they are all of the keyframe's segment): back to the frame's world.
  Eigen::Isometry3d T_later_earlier = Eigen::Isometry3d::Identity();
  for (uint64_t e = epoch; e < f.epoch; ++e) T_later_earlier = epoch_corrections[std::size_t(e)] * T_later_earlier;
  *T_world_graph = it->second;
  *T_world_final = T_later_earlier.inverse() * f.T_world_cam;
  return true;
}

bool LoopRunResult::optimisedPose(const FinishedFrame& frame, Eigen::Isometry3d* T_world_cam) const {
  if (!frame.valid || frame.reference_id == 0) return false;
  Eigen::Isometry3d T_world_ref, T_world_ref_final;
  if (keyframeFinalPose(frame.reference_id, frame.loop_epoch, &T_world_ref, &T_world_ref_final)) {
    // Both in the frame's world: without loops the graph is the local map's final chain, so this
    // is the real-time pose up to one rigid motion, and BA's late changes to a keyframe do not
    // move frames tracked (and output) long before them. With loops, every frame keeps its
    // real-time pose relative to its reference keyframe's final pose, also when a correction
    // came between the two (docs/LOOP.md "Why a correct loop made the optimised trajectory worse").
    *T_world_cam = T_world_ref * T_world_ref_final.inverse() * frame.T_world_cam;
    return true;
  }
  if (!keyframePose(frame.reference_id, &T_world_ref)) return false;
  *T_world_cam = T_world_ref * frame.T_ref_cam;
  return true;
}

bool LoopRunResult::keyframePose(uint32_t id, Eigen::Isometry3d* T_world_cam) const {
  const auto it = std::lower_bound(keyframes.begin(), keyframes.end(), id,
                                   [](const std::pair<uint32_t, Eigen::Isometry3d>& k, uint32_t v) { return k.first < v; });
  if (it == keyframes.end() || it->first != id) return false;
  *T_world_cam = it->second;
  return true;
}

Status runOdometry(FrameCapture& capture, const SystemOptions& system_options, OdometrySink& sink,
                   const OdometryRunOptions& options, OdometryRunResult* result) {
  std::unique_ptr<RunSession> session;
  PLUMB_RETURN_IF_ERROR(RunSession::create(capture.camera(), system_options, sink, options, &session));
  const Status status = session->run(capture);
  *result = session->takeResult();
  return status;
}

}  // namespace plumb

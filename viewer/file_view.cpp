#include "viewer/file_view.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "drivers/trajectory/evaluate.h"
#include "runtime/json_reader.h"
#include "viewer/foxglove_messages.h"
#include "viewer/json_writer.h"
#include "viewer/live_view.h"
#include "viewer/viewer_channels.h"
#include "viewer/viewer_style.h"

namespace plumb::viewer {
namespace {

constexpr std::size_t kMaxFileViewTrajectoryPoints = 20000;  // a view is sent once: more detail than live
constexpr std::size_t kMaxMapPoints = 200000;
constexpr Rgba kEstimateColor = kOutputColor;  // estimate poses without a ground-truth pair

// Green (no error) through yellow to red (the largest error of the run).
Rgba errorColor(double error, double max_error) {
  const double x = max_error > 0 ? std::clamp(error / max_error, 0.0, 1.0) : 0.0;
  if (x < 0.5) return Rgba{float(0.19 + 1.5 * x * 0.83), float(0.75 + 2 * x * 0.07), float(0.38 - 2 * x * 0.13), 1};
  return Rgba{0.94f, float(0.82 - 2 * (x - 0.5) * 0.57), 0.25f, 1};
}

const runtime::JsonValue* member(const runtime::JsonValue& root, std::initializer_list<const char*> path) {
  const runtime::JsonValue* v = &root;
  for (const char* name : path) {
    v = v->find(name);
    if (v == nullptr) return nullptr;
  }
  return v;
}

void copyNumber(JsonWriter& w, const char* key, const runtime::JsonValue& root,
                std::initializer_list<const char*> path) {
  const runtime::JsonValue* v = member(root, path);
  if (v != nullptr && v->isNumber()) w.key(key).number(v->number);
}

// Strips of a trajectory mapped by T, broken at invalid poses; colours per point when `errors`.
void trajectoryStrips(const std::vector<StampedPose>& poses, const Eigen::Isometry3d& T,
                      const std::map<double, double>* errors, double max_error, const Rgba& color,
                      std::vector<LinePrimitive>* out, std::size_t* drawn) {
  std::size_t valid = 0;
  for (const StampedPose& p : poses) valid += p.valid;
  const std::size_t step = valid > kMaxFileViewTrajectoryPoints ? (valid + kMaxFileViewTrajectoryPoints - 1) / kMaxFileViewTrajectoryPoints : 1;
  LinePrimitive strip;
  strip.color = color;
  strip.thickness_px = 4;
  auto flush = [&] {
    if (strip.points.size() >= 2) {
      *drawn += strip.points.size();
      out->push_back(strip);
    }
    strip.points.clear();
    strip.colors.clear();
  };
  std::size_t index = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const StampedPose& p = poses[i];
    if (!p.valid) {
      flush();
      continue;
    }
    const bool last_of_strip = i + 1 == poses.size() || !poses[i + 1].valid;
    if (index++ % step != 0 && !last_of_strip) continue;
    strip.points.push_back((T * p.T_world_cam).translation().cast<float>());
    if (errors != nullptr) {
      const auto it = errors->find(p.timestamp);
      strip.colors.push_back(it == errors->end() ? kEstimateColor : errorColor(it->second, max_error));
    }
  }
  flush();
}

}  // namespace

Status FileView::build(const FileViewInput& in, FileViewSummary* summary) {
  FileViewSummary s;
  runtime::JsonValue stats;
  if (!in.stats_json.empty()) PLUMB_RETURN_IF_ERROR(runtime::parseJson(in.stats_json, &stats).withContext("--stats"));

  // Alignment and per-pose errors when there is ground truth (the ATE's pairs).
  Eigen::Isometry3d T_gt_est = Eigen::Isometry3d::Identity();
  std::map<double, double> error_by_timestamp;  // estimate stamp -> error (m)
  if (!in.ground_truth.empty()) {
    AteResult ate;
    if (evaluateAte(in.ground_truth, in.estimate, AteOptions{}, &ate).ok()) {
      T_gt_est = ate.T_gt_est;
      s.ate_rmse_m = ate.translation_m.rmse;
      s.error_max_m = ate.translation_m.max;
      // Samples carry the ground truth's stamps: each goes to the nearest estimate stamp.
      std::vector<double> stamps;
      for (const StampedPose& p : in.estimate) {
        if (p.valid) stamps.push_back(p.timestamp);
      }
      for (const AteSample& a : ate.samples) {
        const auto it = std::lower_bound(stamps.begin(), stamps.end(), a.timestamp_s);
        double best = 1e300, best_stamp = 0;
        for (auto c : {it, it == stamps.begin() ? it : it - 1}) {
          if (c == stamps.end()) continue;
          if (std::abs(*c - a.timestamp_s) < best) {
            best = std::abs(*c - a.timestamp_s);
            best_stamp = *c;
          }
        }
        if (best < 0.02) error_by_timestamp[best_stamp] = (a.p_world_est_aligned - a.p_world_gt).norm();
      }
    }
  }
  const std::map<double, double>* errors = error_by_timestamp.empty() ? nullptr : &error_by_timestamp;

  LineEntity estimate{"estimate", {}};
  trajectoryStrips(in.estimate, T_gt_est, errors, s.error_max_m, kEstimateColor, &estimate.lines, &s.estimate_poses);
  LineEntity ground_truth{"ground_truth", {}};
  trajectoryStrips(in.ground_truth, Eigen::Isometry3d::Identity(), nullptr, 0, kGroundTruthColor, &ground_truth.lines,
                   &s.ground_truth_poses);
  for (const StampedPose& p : in.estimate) timestamp_s_ = std::max(timestamp_s_, p.timestamp);
  messages_.emplace_back(kTrajectory, sceneUpdateJson(timestamp_s_, {estimate, ground_truth}));
  for (auto it = in.estimate.rbegin(); it != in.estimate.rend(); ++it) {
    if (!it->valid) continue;
    const Eigen::Isometry3d T = T_gt_est * it->T_world_cam;
    messages_.emplace_back(kCameraPose, poseInFrameJson(it->timestamp, T.translation(), Eigen::Quaterniond(T.rotation())));
    break;
  }

  if (in.map != nullptr) {
    const loop::SavedMap& map = *in.map;
    LineEntity frusta{"keyframes", {}};
    LinePrimitive frustum_lines;
    frustum_lines.type = LinePrimitive::kList;
    frustum_lines.color = kKeyframeColor;
    frustum_lines.thickness_px = 1;
    std::map<uint32_t, Eigen::Vector3d> position_by_id;
    std::size_t total_points = 0;
    for (const auto& k : map.keyframes) total_points += k->record.points.size();
    const std::size_t point_step = total_points > kMaxMapPoints ? (total_points + kMaxMapPoints - 1) / kMaxMapPoints : 1;
    std::vector<Eigen::Vector3f> points;
    LinePrimitive segments;
    segments.type = LinePrimitive::kList;
    segments.color = kLineColor;
    segments.thickness_px = 1.5;
    std::size_t point_index = 0;
    for (const auto& k : map.keyframes) {
      const Eigen::Isometry3d T = T_gt_est * k->T_world_cam;
      position_by_id[k->record.id] = T.translation();
      appendFrustum(T.translation().cast<float>(), Eigen::Quaternionf(T.rotation().cast<float>()), kFrustumDepthM,
                    &frustum_lines.points);
      const Eigen::Isometry3f Tf = T.cast<float>();
      for (const loop::LoopPoint& p : k->record.points) {
        if (point_index++ % point_step == 0) points.push_back(Tf * p.P_cam);
      }
      for (const loop::LoopLine& l : k->record.lines) {
        if (l.num_samples < 2) continue;
        segments.points.push_back(Tf * l.samples_cam[0]);
        segments.points.push_back(Tf * l.samples_cam[l.num_samples - 1]);
      }
    }
    s.map_keyframes = map.keyframes.size();
    s.map_points = points.size();
    s.map_lines = segments.points.size() / 2;
    frusta.lines.push_back(std::move(frustum_lines));
    LineEntity loops{"loops", {}};
    LinePrimitive edges;
    edges.type = LinePrimitive::kList;
    edges.color = kLoopColor;
    edges.thickness_px = 3;
    for (const loop::SavedLoopEdge& e : map.loop_edges) {
      const auto a = position_by_id.find(e.candidate_id), b = position_by_id.find(e.query_id);
      if (a == position_by_id.end() || b == position_by_id.end()) continue;
      edges.points.push_back(a->second.cast<float>());
      edges.points.push_back(b->second.cast<float>());
      ++s.loop_edges;
    }
    loops.lines.push_back(std::move(edges));
    LineEntity lines{"map_lines", {}};
    lines.lines.push_back(std::move(segments));
    messages_.emplace_back(kKeyframes, sceneUpdateJson(timestamp_s_, {frusta}));
    messages_.emplace_back(kLoops, sceneUpdateJson(timestamp_s_, {loops}));
    messages_.emplace_back(kMapPoints, pointCloudJson(timestamp_s_, points));
    messages_.emplace_back(kMapLines, sceneUpdateJson(timestamp_s_, {lines}));
  }

  JsonWriter w;
  w.beginObject();
  w.key("timestamp").beginObject().key("sec").number(uint64_t(std::max(0.0, std::floor(timestamp_s_))));
  w.key("nsec").number(0).endObject();
  const runtime::JsonValue* mode = member(stats, {"options", "mode"});
  w.key("mode").string(mode != nullptr && mode->isString() ? "view of a " + mode->string + " run" : "view");
  const runtime::JsonValue* source = member(stats, {"source"});
  w.key("source").string(source != nullptr && source->isString() ? source->string : in.title);
  w.key("state").string("ended");
  w.key("frame").number(uint64_t(in.estimate.size()));
  w.key("frame_timestamp").number(timestamp_s_);
  w.key("frames").number(uint64_t(in.estimate.size()));
  std::size_t lost = 0, dropped = 0;
  for (const StampedPose& p : in.estimate) {
    lost += !p.valid && !p.dropped;
    dropped += p.dropped;
  }
  w.key("frames_lost").number(uint64_t(lost));
  w.key("frames_dropped").number(uint64_t(dropped));
  w.key("loops").number(uint64_t(s.loop_edges));
  w.key("map_points").number(uint64_t(s.map_points));
  w.key("map_lines").number(uint64_t(s.map_lines));
  w.key("point_inliers").number(0);
  w.key("line_inliers").number(0);
  w.key("latency_ms").number(-1.0);
  copyNumber(w, "keyframes", stats, {"keyframes"});
  copyNumber(w, "relocalizations", stats, {"relocalizations"});
  copyNumber(w, "latency_p99_ms", stats, {"ms_per_frame", "total", "p99"});
  w.key("ate_rmse_m").number(s.ate_rmse_m);
  w.key("error_max_m").number(s.error_max_m);
  status_prefix_ = w.text();  // left open: the clients count is added per tick
  *summary = s;
  return Status::Ok();
}

void FileView::tick(FoxgloveServer& server) {
  const uint64_t t_ns = uint64_t(std::llround(std::max(0.0, timestamp_s_) * 1e9));
  if (!published_) {
    published_ = true;
    for (const auto& [channel, json] : messages_) server.publish(channel, t_ns, json);
  }
  // Once a second: how many watch.
  if (ticks_++ % 30 != 0) return;
  server.publish(kStatus, t_ns,
                 status_prefix_ + ",\"clients\":" + std::to_string(server.clientCount()) + "}");
}

}  // namespace plumb::viewer

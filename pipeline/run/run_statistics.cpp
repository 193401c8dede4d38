#include "pipeline/run/run_statistics.h"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>

#include "pipeline/odometry/map_capacities.h"
#include "pipeline/run/loop_audit_json.h"
#include "platform/process_memory.h"
#include "runtime/json_text.h"

namespace plumb {

RunStatistics::RunStatistics(long rss_every, std::size_t max_checkpoints)
    : rss_every_(rss_every), max_checkpoints_(max_checkpoints) {
  if (rss_every_ > 0) rss_.reserve(max_checkpoints_);
}

void RunStatistics::add(const FrameOutput& frame) {
  if (frame.dropped) {
    ++frames_dropped_;
    return;
  }
  ++frames_;
  auto ns = [](double ms) { return static_cast<int64_t>(std::llround(ms * 1e6)); };
  extract_.add(ns(frame.extract_ms));
  track_.add(ns(frame.track_ms));
  map_.add(ns(frame.map_ms));
  if (frame.register_ms > 0) {
    ++frames_registered_;
    register_.add(ns(frame.register_ms));
  }
  total_.add(ns(frame.register_ms + frame.extract_ms + frame.track_ms + frame.map_ms));
  if (rss_every_ > 0 && frames_ % uint64_t(rss_every_) == 0 && rss_.size() < max_checkpoints_) {
    RssCheckpoint c;
    c.frame = frames_;
    if (readRss(&c.peak_rss_kib, &c.current_rss_kib)) rss_.push_back(c);
  }
}


std::string runSummaryJson(const RunSummary& r) {
  using runtime::jsonNumber;
  using runtime::jsonString;
  const OdometryStats& s = r.odometry;
  const MapperStats& m = r.mapper;
  const OdometryOptions& o = r.system_options.odometry;
  std::string out;
  char buf[640];
  auto add = [&out, &buf](int n) { out.append(buf, std::size_t(std::max(0, std::min(n, int(sizeof(buf)) - 1)))); };
  out += "{\n  \"source\": " + jsonString(r.source) + ",\n";
  add(std::snprintf(buf, sizeof(buf), "  \"frames\": %" PRIu64 ", \"frames_dropped\": %" PRIu64
                    ", \"extraction_failures\": %" PRIu64 ",\n  \"stopped_by_signal\": %s, \"stop_signal\": %d,\n",
                    r.statistics->frames(), r.statistics->framesDropped(), r.run->extraction_failures,
                    r.run->stopped ? "true" : "false", r.stop_signal));
  add(std::snprintf(buf, sizeof(buf), "  \"input_damaged_regions\": %" PRIu64 ", \"input_damage\": ", r.damaged_regions));
  out += (r.damage.empty() ? std::string("null") : jsonString(r.damage)) + ",\n";
  add(std::snprintf(buf, sizeof(buf),
                    "  \"tracking\": {\"ok\": %" PRIu64 ", \"weak\": %" PRIu64 ", \"lost\": %" PRIu64
                    ", \"not_initialized\": %" PRIu64 ", \"motion_fallback\": %" PRIu64 "},\n",
                    s.frames_ok, s.frames_weak, s.frames_lost, s.frames_not_initialized, s.frames_motion_fallback));
  add(std::snprintf(buf, sizeof(buf),
                    "  \"keyframes\": %" PRIu64 ", \"segments\": %" PRIu64 ", \"relocalizations\": %" PRIu64
                    ", \"relocalization_attempts\": %" PRIu64 ",\n",
                    s.keyframes, s.segments, s.relocalizations, s.relocalization_attempts));
  add(std::snprintf(buf, sizeof(buf),
                    "  \"map\": {\"points_created\": %" PRIu64 ", \"lines_created\": %" PRIu64
                    ", \"points_culled\": %" PRIu64 ", \"lines_culled\": %" PRIu64 ", \"ba_runs\": %" PRIu64
                    ", \"ba_outlier_flags\": %" PRIu64 ", \"ba_outlier_observations\": %" PRIu64
                    ", \"ba_covariances_refused\": %" PRIu64 ",\n",
                    m.points_created, m.lines_created, m.points_culled, m.lines_culled, m.ba_runs,
                    m.ba_outlier_flags, m.ba_outlier_observations, m.ba_covariances_refused));
  add(std::snprintf(buf, sizeof(buf),
                    "          \"peak\": {\"keyframes\": %zu, \"points\": %zu, \"lines\": %zu, "
                    "\"point_observations\": %zu, \"line_observations\": %zu},\n",
                    m.peak.keyframes, m.peak.points, m.peak.lines, m.peak.point_observations,
                    m.peak.line_observations));
  add(std::snprintf(buf, sizeof(buf),
                    "          \"capacity\": {\"keyframes\": %zu, \"points\": %zu, \"lines\": %zu}},\n",
                    kMaxMapKeyframes, kMaxMapPoints, kMaxMapLines));
  auto timing = [&](const char* name, const runtime::LatencyHistogram& h, bool last) {
    add(std::snprintf(buf, sizeof(buf), "    \"%s\": {\"mean\": %.3f, \"p50\": %.3f, \"p99\": %.3f, \"max\": %.3f}%s\n",
                      name, h.meanNs() * 1e-6, double(h.percentileNs(0.5)) * 1e-6,
                      double(h.percentileNs(0.99)) * 1e-6, double(h.maxNs()) * 1e-6, last ? "" : ","));
  };
  out += "  \"ms_per_frame\": {\n";
  timing("total", r.statistics->totalNs(), false);
  // Only runs that registered depth have the row, so the statistics of others are unchanged.
  if (r.statistics->framesRegistered() > 0) timing("register", r.statistics->registerNs(), false);
  timing("extract", r.statistics->extractNs(), false);
  timing("track", r.statistics->trackNs(), false);
  timing("map", r.statistics->mapNs(), true);
  out += "  },\n";
  // The options the run actually used (after defaults and flags), so a result can be reproduced.
  add(std::snprintf(buf, sizeof(buf),
                    "  \"options\": {\"mode\": \"%s\", \"slots\": %zu, \"max_frames\": %ld, \"output_delay_frames\": %d,\n"
                    "              \"line_samples\": %d, \"lines\": %s, \"min_line_inliers\": %d, \"num_features\": %d,\n"
                    "              \"pyramid_levels\": %d, \"max_lines\": %d, \"ba_keyframes\": %d, \"ba_iterations\": %d},\n",
                    runtime::runModeName(r.run_options.schedule.mode), r.run_options.schedule.slot_count,
                    r.run_options.max_frames, r.system_options.output_delay_frames, o.extractor.line_samples,
                    o.tracker.use_lines ? "true" : "false", o.extractor.min_line_inliers, o.extractor.num_features,
                    o.extractor.num_levels, o.extractor.max_lines, o.mapper.ba_optimised_keyframes,
                    o.mapper.ba_iterations));
  if (!r.command_options.empty()) {
    out += "  \"command_options\": {";
    for (std::size_t i = 0; i < r.command_options.size(); ++i) {
      out += (i ? ", " : "") + jsonString(r.command_options[i].first) + ": " + r.command_options[i].second;
    }
    out += "},\n";
  }
  // Loop closing (docs/LOOP.md): graph size, loops found and rejected by reason, optimisation time.
  const LoopRunResult& lr = r.run->loop;
  if (!lr.enabled) {
    out += "  \"loop_closing\": {\"enabled\": false},\n";
  } else {
    const loop::LoopStats& ls = lr.stats;
    add(std::snprintf(buf, sizeof(buf),
                      "  \"loop_closing\": {\"enabled\": true, \"graph_keyframes\": %" PRIu64 ", \"peak_graph_keyframes\": %" PRIu64
                      ", \"capacity\": %zu, \"memory_bytes\": %zu, \"keyframes_received\": %" PRIu64
                      ", \"records_dropped\": %" PRIu64 ", \"culled\": %" PRIu64 ",\n",
                      ls.graph_nodes, ls.peak_graph_nodes, lr.capacity, lr.memory_bytes, ls.keyframes,
                      lr.records_dropped, ls.culled));
    add(std::snprintf(buf, sizeof(buf),
                      "    \"queries\": %" PRIu64 ", \"consistent_candidates\": %" PRIu64 ", \"verifications\": %" PRIu64
                      ", \"loops_found\": %" PRIu64 ", \"loop_edges\": %" PRIu64 ", \"corrections_applied\": %" PRIu64
                      ", \"corrections_stale\": %" PRIu64 ",\n",
                      ls.queries, ls.consistent_candidates, ls.verifications, ls.loops_accepted, ls.loop_edges,
                      s.loop_corrections_applied, s.loop_corrections_stale));
    out += "    \"loops_rejected\": {";
    for (int i = 1; i < loop::kNumLoopRejections; ++i) {
      add(std::snprintf(buf, sizeof(buf), "%s\"%s\": %" PRIu64, i > 1 ? ", " : "",
                        loop::toString(loop::LoopRejection(i)), ls.rejected[i]));
    }
    out += "},\n";
    add(std::snprintf(buf, sizeof(buf),
                      "    \"edges_refined\": %" PRIu64 ", \"edge_covariances_refused\": %" PRIu64
                      ", \"optimisations\": %" PRIu64 ", \"optimisation_ms_total\": %.3f, \"optimisation_ms_max\": %.3f},\n",
                      ls.edges_refined, ls.edge_covariances_refused, ls.optimisations, ls.optimisation_ms_total,
                      ls.optimisation_ms_max));
    out += loopAuditJson(lr) + ",\n";
  }
  if (r.map_loaded || !r.map_saved_path.empty()) {
    add(std::snprintf(buf, sizeof(buf),
                      "  \"map_file\": {\"loaded\": %s, \"load_read_ms\": %.3f, \"load_restore_ms\": %.3f, "
                      "\"loaded_keyframes\": %" PRIu64 ", \"loaded_loop_edges\": %" PRIu64
                      ", \"relocalized_frame\": %" PRId64 ", \"saved_keyframes\": %" PRIu64 ", \"saved_bytes\": %" PRIu64 "},\n",
                      r.map_loaded ? "true" : "false", r.map_read_ms, r.run->map_restore_ms, r.map_keyframes,
                      r.map_loop_edges, s.loaded_map_relocalized_frame, r.map_saved_keyframes, r.map_saved_bytes));
  }
  if (!r.source_supervision_json.empty()) out += "  \"source_supervision\": " + r.source_supervision_json + ",\n";
  out += "  \"rss_checkpoints\": [";
  const std::vector<RssCheckpoint>& rss = r.statistics->rss();
  for (std::size_t i = 0; i < rss.size(); ++i) {
    add(std::snprintf(buf, sizeof(buf), "%s{\"frame\": %" PRIu64 ", \"peak_kib\": %ld, \"current_kib\": %ld}",
                      i ? ", " : "", rss[i].frame, rss[i].peak_rss_kib, rss[i].current_rss_kib));
  }
  out += "],\n";
  out += "  \"ate_rmse_m\": " + (r.ate_rmse_m >= 0 ? jsonNumber(r.ate_rmse_m) : std::string("null")) + "\n}\n";
  return out;
}

}  // namespace plumb

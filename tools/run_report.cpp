// `plumb run`, step 4 of 4 (tools/run_command.h): what the run produced, printed and written
// (summary lines, ATE, --profile, --stats), and the exit code.
#include <cstdio>
#include <string>

#include "drivers/synth/synth_spec.h"
#include "drivers/trajectory/evaluate.h"
#include "drivers/common/atomic_file.h"
#include "runtime/chrome_trace.h"
#include "tools/command.h"
#include "tools/run_command.h"

namespace plumb::tools {
namespace {

int fail(const std::string& message) {
  std::fprintf(stderr, "plumb run: %s\n", message.c_str());
  return kExitFailed;
}

// What happened to the outputs, for the message of a run that failed or was stopped: never "the
// poses were written" when they were not.
std::string outputsNote(const RunOutputs& outputs, const RunExecution& ex) {
  const std::string frames = std::to_string(outputs.statistics().frames()) + " frames processed";
  if (!outputs.anyFile()) return frames;
  if (!ex.record.outputs_kept) return "no frame processed; no output was written, existing files are unchanged";
  if (!ex.record.outputs_status.ok()) {
    return frames + "; the outputs could NOT be written (" + ex.record.outputs_status.message() + ")";
  }
  return frames + "; their poses were written";
}

void printDamage(const SourceDamage& damage) {
  std::fprintf(stderr,
               "plumb run: WARNING: the input is damaged: %llu damaged region(s) skipped (%llu bytes), %llu bytes "
               "of incomplete tail, %s; last: %s. Frames in damaged regions have no trajectory line.\n",
               (unsigned long long)damage.regions_skipped, (unsigned long long)damage.bytes_skipped,
               (unsigned long long)damage.truncated_tail_bytes,
               damage.closed_properly ? "closed properly" : "not closed properly",
               damage.last.empty() ? "-" : damage.last.c_str());
}

// ATE of the trajectory and of the optimised one (-1: none).
void computeAte(const RunCommandOptions& o, const RunPlan& plan, const RunOutputs& outputs, double* ate,
                double* ate_optimized) {
  *ate = *ate_optimized = -1;
  std::vector<StampedPose> scene_truth;
  const std::vector<StampedPose>* ground_truth = &plan.ground_truth;
  if (o.gt.empty() && plan.scene != nullptr) {
    // The scene's exact poses of the frames the run saw: never more than the scene has (a skip
    // beyond its end is not a size to allocate).
    const RunStatistics& s = outputs.statistics();
    const long long seen = (long long)(s.frames() + s.framesDropped()) + o.skip_frames;
    scene_truth = syntheticGroundTruth(*plan.scene, long(std::min<long long>(seen, plan.scene->numFrames())));
    ground_truth = &scene_truth;
  }
  if (ground_truth->empty() || !plan.output_options.keep_trajectory) return;
  AteResult result;
  const Status st = evaluateAte(*ground_truth, outputs.trajectory(), AteOptions{}, &result);
  if (st.ok()) {
    *ate = result.translation_m.rmse;
  } else {
    std::fprintf(stderr, "plumb run: no ATE: %s\n", st.message().c_str());
  }
  if (!outputs.optimizedTrajectory().empty() &&
      evaluateAte(*ground_truth, outputs.optimizedTrajectory(), AteOptions{}, &result).ok()) {
    *ate_optimized = result.translation_m.rmse;
  }
}

void printSummary(const RunCommandOptions& o, const RunPlan& plan, const RunOutputs& outputs, const RunExecution& ex) {
  const RunStatistics& statistics = outputs.statistics();
  const RunRecord& record = ex.record;
  const OdometryStats& s = record.odometry;
  std::printf("frames %llu: ok %llu, weak %llu, lost %llu, not initialized %llu; keyframes %llu, "
              "relocalizations %llu, map segments %llu\n",
              (unsigned long long)statistics.frames(), (unsigned long long)s.frames_ok,
              (unsigned long long)s.frames_weak, (unsigned long long)s.frames_lost,
              (unsigned long long)s.frames_not_initialized, (unsigned long long)s.keyframes,
              (unsigned long long)s.relocalizations, (unsigned long long)s.segments);
  std::printf("ms per frame: mean %.2f, p99 %.2f (extract %.2f, track %.2f, map %.2f mean)\n",
              statistics.totalNs().meanNs() * 1e-6, double(statistics.totalNs().percentileNs(0.99)) * 1e-6,
              statistics.extractNs().meanNs() * 1e-6, statistics.trackNs().meanNs() * 1e-6,
              statistics.mapNs().meanNs() * 1e-6);
  const runtime::RunReport& report = record.run.report;
  std::printf("%s: %.1f frames/s, dropped %llu, late %llu, extraction failures %llu, waits for the mapper %llu\n",
              runtime::runModeName(plan.run_options.schedule.mode), report.framesPerSecond(),
              (unsigned long long)report.frames_dropped, (unsigned long long)report.frames_late,
              (unsigned long long)record.run.extraction_failures, (unsigned long long)record.mapper_waits);
  if (o.count_allocations) {
    if (record.run.allocation_frames == 0) {
      std::printf("allocations: run not longer than the %llu-frame warm-up\n",
                  (unsigned long long)plan.run_options.warmup_frames);
    } else {
      std::printf("allocations after warm-up: %llu over %llu frames (%.2f per frame)\n",
                  (unsigned long long)record.run.allocations_after_warmup,
                  (unsigned long long)record.run.allocation_frames,
                  double(record.run.allocations_after_warmup) / double(record.run.allocation_frames));
    }
  }
  if (const MavlinkOdometrySink* mavlink = outputs.mavlink()) {
    const MavlinkStats& m = mavlink->stats();
    std::printf("mavlink %s: odometry sent %llu, heartbeats %llu, dropped %llu, no pose %llu, resets %llu\n",
                o.mavlink.c_str(), (unsigned long long)m.odometry_sent, (unsigned long long)m.heartbeats_sent,
                (unsigned long long)m.dropped, (unsigned long long)m.skipped_no_pose, (unsigned long long)m.resets);
  }
  const LoopRunResult& loop = record.run.loop;
  if (loop.enabled) {
    const loop::LoopStats& ls = loop.stats;
    uint64_t rejected = 0;
    for (int i = 1; i < loop::kNumLoopRejections; ++i) rejected += ls.rejected[i];
    std::printf("loop closing: graph %llu keyframes (capacity %zu), loops found %llu, rejected %llu "
                "(implausible %llu), optimisation %.1f ms total, records dropped %llu\n",
                (unsigned long long)ls.graph_nodes, loop.capacity, (unsigned long long)ls.loops_accepted,
                (unsigned long long)rejected, (unsigned long long)ls.rejected[int(loop::LoopRejection::kImplausible)],
                ls.optimisation_ms_total, (unsigned long long)loop.records_dropped);
  }
  if (!o.load_map.empty()) {
    const int64_t relocalized = s.loaded_map_relocalized_frame;
    std::printf("map loaded: %s, %zu keyframes, %zu loop edges; read + checked in %.1f ms, restored in %.1f ms; ",
                o.load_map.c_str(), plan.loaded_map.keyframes.size(), plan.loaded_map.loop_edges.size(),
                plan.map_read_ms, record.run.map_restore_ms);
    if (relocalized >= 0) {
      std::printf("relocalized at frame %lld\n", (long long)relocalized);
    } else {
      std::printf("never relocalized\n");
    }
  }
}

// A supervised live source's outages, for --stats: how many, how long, and how soon a camera's
// USB arrival brought frames back. "" for sources that are not supervised (replays).
std::string supervisionJson(const FrameSource& source) {
  SourceSupervision s;
  if (!source.supervision(&s)) return "";
  char text[640];
  std::snprintf(text, sizeof text,
                "{\"outages\": %llu, \"reconnects\": %llu, \"errors\": %llu, \"stall_timeouts\": %llu, "
                "\"reopen_failures\": %llu, \"usb_departures\": %llu, \"usb_arrivals\": %llu,\n"
                "    \"disconnected_s\": %.3f, \"longest_outage_s\": %.3f, \"arrival_to_first_frame_s\": %s, "
                "\"frames_missing\": %llu, \"gaps\": %llu}",
                (unsigned long long)s.outages, (unsigned long long)s.reconnects, (unsigned long long)s.errors,
                (unsigned long long)s.stall_timeouts, (unsigned long long)s.reopen_failures,
                (unsigned long long)s.usb_departures, (unsigned long long)s.usb_arrivals, s.disconnected_ns * 1e-9,
                s.longest_outage_ns * 1e-9,
                s.arrival_to_frame_ns < 0 ? "null" : std::to_string(s.arrival_to_frame_ns * 1e-9).c_str(),
                (unsigned long long)s.frames_missing, (unsigned long long)s.gaps);
  return text;
}

Status writeStats(const RunCommandOptions& o, const FlagTable& table, const RunPlan& plan, const RunOutputs& outputs,
                  const RunExecution& ex, const SourceDamage& damage, double ate, int stop_signal) {
  RunSummary summary;
  summary.source = plan.source->describe();
  summary.statistics = &outputs.statistics();
  summary.run = &ex.record.run;
  summary.odometry = ex.record.odometry;
  summary.mapper = ex.record.mapper;
  summary.system_options = plan.system_options;
  summary.run_options = plan.run_options;
  summary.command_options = table.jsonValues();
  summary.ate_rmse_m = ate;
  summary.stop_signal = ex.record.run.stopped ? stop_signal : 0;
  summary.damaged_regions = damage.regions_skipped;
  summary.damage = damage.last;
  summary.map_loaded = !o.load_map.empty();
  summary.map_read_ms = plan.map_read_ms;
  summary.map_keyframes = plan.loaded_map.keyframes.size();
  summary.map_loop_edges = plan.loaded_map.loop_edges.size();
  if (ex.map_saved) {
    summary.map_saved_path = o.save_map;
    summary.map_saved_keyframes = plan.saved_map.keyframes.size();
    summary.map_saved_bytes = ex.map_bytes;
  }
  summary.source_supervision_json = supervisionJson(*plan.source);
  return writeFileAtomically(o.stats, runSummaryJson(summary));
}

}  // namespace

int reportRun(const RunCommandOptions& o, const FlagTable& table, RunPlan& plan, const RunOutputs& outputs,
              RunExecution& ex, int stop_signal) {
  const RunRecord& record = ex.record;
  if (ex.map_saved) {
    std::printf("map saved: %s, %zu keyframes, %zu loop edges, %llu bytes\n", o.save_map.c_str(),
                plan.saved_map.keyframes.size(), plan.saved_map.loop_edges.size(), (unsigned long long)ex.map_bytes);
  } else if (!ex.map_note.empty() && ex.status.ok()) {
    std::fprintf(stderr, "plumb run: %s\n", ex.map_note.c_str());
  }
  // Live sources: what supervision and capture counted (faults, reconnects, pairing), also after a
  // failed run.
  const std::string source_health = plan.source->healthReport();
  if (!source_health.empty()) std::printf("%s\n", source_health.c_str());
  const SourceDamage damage = plan.source->damage();
  if (!ex.status.ok()) {
    if (damage.any()) printDamage(damage);
    std::string message = ex.status.message() + " (" + outputsNote(outputs, ex) + ")";
    if (!ex.map_note.empty() && !ex.map_saved && ex.map_note != ex.status.message()) message += "; " + ex.map_note;
    return fail(message);
  }
  if (damage.any()) printDamage(damage);
  // A run over an input that held no readable frame is a failed run, not an empty success.
  if (outputs.statistics().frames() + outputs.statistics().framesDropped() == 0 && !record.run.stopped) {
    return fail(plan.source->describe() + ": no readable frame" +
                (damage.any() ? std::string(" (every frame was damaged)") : std::string(" (the input holds no frame to run)")) +
                "; no output was written, existing files are unchanged");
  }

  double ate = -1, ate_optimized = -1;
  computeAte(o, plan, outputs, &ate, &ate_optimized);
  printSummary(o, plan, outputs, ex);
  if (ate >= 0) std::printf("ATE RMSE %.4f m\n", ate);
  if (ate_optimized >= 0) std::printf("ATE RMSE optimized %.4f m\n", ate_optimized);
  if (!o.profile.empty()) {
    const runtime::RunReport& report = record.run.report;
    const Status st = writeFileAtomically(o.profile, runtime::formatChromeTrace(record.run.trace, report));
    if (!st.ok()) return fail(st.message());
    std::printf("%s", runtime::formatRunReport(report).c_str());
    std::printf("trace: %s (open in ui.perfetto.dev; `plumb profile %s --png hist.png`)\n", o.profile.c_str(),
                o.profile.c_str());
  }
  if (!o.stats.empty()) {
    const Status st = writeStats(o, table, plan, outputs, ex, damage, ate, stop_signal);
    if (!st.ok()) return fail(st.message());
  }
  if (record.run.stopped) {
    std::fprintf(stderr, "plumb run: stopped by signal %d after %llu frames; %s\n", stop_signal,
                 (unsigned long long)outputs.statistics().frames(),
                 outputs.anyFile() && !record.outputs_kept
                     ? "no frame was processed, so no trajectory file was replaced"
                     : "every pose computed was written");
    return kExitStopped;
  }
  return kExitOk;
}

}  // namespace plumb::tools

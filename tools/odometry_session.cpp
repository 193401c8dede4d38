#include "tools/odometry_session.h"

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>

#include <opencv2/core/utility.hpp>

#include "drivers/dataset/tum_dataset.h"
#include "platform/allocation_counter.h"

namespace plumb::tools {

void MsHistogram::add(double ms) {
  const int bin = std::min(kBins, std::max(0, int(ms / kBinMs)));
  ++bins_[std::size_t(bin)];
  ++count_;
  sum_ += ms;
  max_ = std::max(max_, ms);
}

double MsHistogram::percentile(double p) const {
  if (count_ == 0) return 0.0;
  const uint64_t rank = uint64_t(p / 100.0 * double(count_ - 1));
  uint64_t seen = 0;
  for (int i = 0; i <= kBins; ++i) {
    seen += bins_[std::size_t(i)];
    if (seen > rank) return (i + 0.5) * kBinMs;  // bin centre
  }
  return max_;
}

bool readRss(long* peak_kib, long* current_kib) {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (f == nullptr) return false;
  char line[256];
  *peak_kib = *current_kib = -1;
  while (std::fgets(line, sizeof(line), f)) {
    if (std::strncmp(line, "VmHWM:", 6) == 0) *peak_kib = std::strtol(line + 6, nullptr, 10);
    if (std::strncmp(line, "VmRSS:", 6) == 0) *current_kib = std::strtol(line + 6, nullptr, 10);
  }
  std::fclose(f);
  return *peak_kib >= 0 && *current_kib >= 0;
}

namespace {

// Covariance file: `timestamp c00 c01 .. c05 c11 .. c55` (the 21 upper-triangle entries, row by
// row) per keyframe, in the order keyframes leave the map; keyframes BA never gave a covariance
// are written as `# <timestamp> no covariance`.
class CovarianceWriter {
 public:
  Status open(const std::string& path) {
    if (path.empty()) return Status::Ok();
    file_ = std::fopen(path.c_str(), "w");
    if (file_ == nullptr) return Status::Error(path + ": cannot open for writing");
    path_ = path;
    std::fprintf(file_,
                 "# plumb keyframe pose covariance: timestamp then the 21 upper-triangle entries of the 6x6\n"
                 "# covariance of the left perturbation [rho(3) phi(3)] of T_cam_world, row by row\n");
    return Status::Ok();
  }
  void write(const RetiredKeyframe& kf) {
    if (file_ == nullptr) return;
    if (!kf.covariance_valid) {
      std::fprintf(file_, "# %.6f no covariance\n", kf.timestamp_s);
      return;
    }
    std::fprintf(file_, "%.6f", kf.timestamp_s);
    for (int r = 0; r < 6; ++r) {
      for (int c = r; c < 6; ++c) std::fprintf(file_, " %.9g", kf.covariance(r, c));
    }
    std::fprintf(file_, "\n");
  }
  Status close() {
    if (file_ == nullptr) return Status::Ok();
    const bool ok = std::fclose(file_) == 0;
    file_ = nullptr;
    return ok ? Status::Ok() : Status::Error(path_ + ": write failed");
  }
  ~CovarianceWriter() { (void)close(); }

 private:
  std::FILE* file_ = nullptr;
  std::string path_;
};

// Frames the source will deliver when that is known in advance (a synthetic scene, a TUM-layout
// folder), capped by max_frames; 0 when unknown (live sensors, recordings).
std::size_t expectedFrames(FrameSource& source, long max_frames) {
  std::size_t frames = 0;
  if (auto* synthetic = dynamic_cast<SyntheticSource*>(&source)) frames = std::size_t(synthetic->scene().numFrames());
  if (auto* replay = dynamic_cast<TumDatasetSource*>(&source)) frames = replay->size();
  if (max_frames >= 0 && (frames == 0 || std::size_t(max_frames) < frames)) frames = std::size_t(max_frames);
  return frames;
}

}  // namespace

Status runSession(FrameSource& source, const SessionOptions& options, SessionResult* result) {
  result->source = source.describe();
  // Reserved once so keeping poses for the ATE costs no allocation per frame (the steady-state
  // allocation test runs with it on). Sources of unknown length still grow the vector.
  if (options.keep_trajectory) result->trajectory.reserve(expectedFrames(source, options.max_frames));
  auto system = std::make_unique<OdometrySystem>(source.camera(), options.system);
  TumTrajectoryWriter trajectory_writer;
  if (!options.trajectory_path.empty()) PLUMB_RETURN_IF_ERROR(trajectory_writer.open(options.trajectory_path));
  CovarianceWriter covariance_writer;
  PLUMB_RETURN_IF_ERROR(covariance_writer.open(options.covariance_path));

  Status write_status;
  auto on_frame = [&](const FinishedFrame& f) {
    StampedPose pose;
    pose.timestamp = f.timestamp_s;
    pose.T_world_cam = f.T_world_cam;
    pose.valid = f.valid;
    pose.dropped = f.dropped;
    if (options.keep_trajectory) result->trajectory.push_back(pose);
    if (!options.trajectory_path.empty() && write_status.ok()) write_status = trajectory_writer.append(pose);
  };
  auto on_keyframe = [&](const RetiredKeyframe& kf) { covariance_writer.write(kf); };

  // Bookkeeping after each frame, identical for the single-threaded loop and the staged run (where
  // it runs on the odometry stage's thread, in frame order): statistics, drained output, checks.
  uint64_t allocations_at_warmup = 0;
  auto after_frame = [&](const FrameOutput& out) -> Status {
    if (out.dropped) {  // realtime: only its place in the trajectory (`# <t> dropped`)
      ++result->frames_dropped;
      system->drainFinishedFrames(on_frame);
      return write_status;
    }
    ++result->frames;
    result->extract_ms.add(out.extract_ms);
    result->track_ms.add(out.track_ms);
    result->map_ms.add(out.map_ms);
    result->total_ms.add(out.extract_ms + out.track_ms + out.map_ms);
    system->drainFinishedFrames(on_frame);
    system->drainRetiredKeyframes(on_keyframe);
    PLUMB_RETURN_IF_ERROR(write_status);
    if (options.rss_every > 0 && result->frames % options.rss_every == 0) {
      RssCheckpoint c;
      c.frame = result->frames;
      if (readRss(&c.peak_rss_kib, &c.current_rss_kib)) result->rss.push_back(c);
    }
    if (options.trace) {
      const Eigen::Vector3d t = out.T_world_cam.translation();
      std::fprintf(stderr, "%ld %s fm %d lm %d pi %d li %d lmi %d kf %d np %d nl %d reloc %d fb %d t %.3f %.3f %.3f\n",
                   result->frames, toString(out.state), out.track.frame_matches, out.track.local_map_matches,
                   out.track.point_inliers, out.track.line_inliers, out.track.landmark_inliers, out.keyframe,
                   out.insert.new_points, out.insert.new_lines, out.relocalized, out.track.used_motion_fallback,
                   t.x(), t.y(), t.z());
    }
    if (options.progress && result->frames % 100 == 0) {
      std::fprintf(stderr, "frame %ld: %s, keyframes %" PRIu64 ", lost %" PRIu64 "\n", result->frames,
                   toString(out.state), system->stats().keyframes, system->stats().frames_lost);
    }
    // Last, so the count covers everything a frame costs, this bookkeeping included.
    if (options.count_allocations) {
      const uint64_t frames = uint64_t(result->frames);
      const uint64_t now = allocationCount();
      if (frames == options.staged.warmup_frames) allocations_at_warmup = now;
      if (frames > options.staged.warmup_frames) {
        result->allocation_frames = frames - options.staged.warmup_frames;
        result->allocations_after_warmup = now - allocations_at_warmup;
      }
    }
    return Status::Ok();
  };

  if (options.use_stages) {
    // The stages are the parallelism: OpenCV's own worker pool (TBB) would compete with them for
    // the cores, and each fresh pool worker allocates thread-local state (cv::theRNG) the first
    // time a cv::parallel_for_ body runs on it, i.e. at unpredictable frames of a steady run.
    cv::setNumThreads(0);
    StagedRunOptions staged = options.staged;
    staged.max_frames = options.max_frames;
    PLUMB_RETURN_IF_ERROR(runStaged(source, *system, staged, after_frame, &result->staged));
    if (options.count_allocations) {
      // The stage's window (see SessionResult): the first counted frame is the baseline.
      result->allocation_frames = result->staged.frames_after_warmup > 0 ? result->staged.frames_after_warmup - 1 : 0;
      result->allocations_after_warmup = result->staged.allocations_after_warmup;
    }
  } else {
    RgbdImage image;
    while (options.max_frames < 0 || result->frames < options.max_frames) {
      const SourceResult r = source.next(image);
      if (r == SourceResult::kEndOfStream) break;
      if (r == SourceResult::kNoFrame) continue;
      if (r == SourceResult::kError) return source.lastError().withContext(source.describe());
      PLUMB_RETURN_IF_ERROR(after_frame(system->processImage(image)));
    }
  }
  system->finish(on_frame, on_keyframe);
  PLUMB_RETURN_IF_ERROR(write_status);
  if (!options.trajectory_path.empty()) PLUMB_RETURN_IF_ERROR(trajectory_writer.close());
  PLUMB_RETURN_IF_ERROR(covariance_writer.close());
  result->stats = system->stats();
  result->mapper = system->mapperStats();
  result->final_counts = system->mapCounts();
  return Status::Ok();
}

std::string sessionJson(const SessionResult& r, const SessionOptions& options, double ate_rmse_m) {
  const OdometryStats& s = r.stats;
  const MapperStats& m = r.mapper;
  std::string out;
  char buf[512];
  auto add = [&out, &buf](int n) { out.append(buf, std::size_t(std::max(0, std::min(n, int(sizeof(buf)) - 1)))); };
  add(std::snprintf(buf, sizeof(buf), "{\n  \"source\": \"%s\",\n  \"frames\": %ld,\n", r.source.c_str(), r.frames));
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
                    ", \"ba_outlier_observations\": %" PRIu64 ",\n",
                    m.points_created, m.lines_created, m.points_culled, m.lines_culled, m.ba_runs,
                    m.ba_outlier_observations));
  add(std::snprintf(buf, sizeof(buf),
                    "          \"peak\": {\"keyframes\": %zu, \"points\": %zu, \"lines\": %zu, "
                    "\"point_observations\": %zu, \"line_observations\": %zu},\n",
                    m.peak.keyframes, m.peak.points, m.peak.lines, m.peak.point_observations,
                    m.peak.line_observations));
  add(std::snprintf(buf, sizeof(buf),
                    "          \"capacity\": {\"keyframes\": %zu, \"points\": %zu, \"lines\": %zu}},\n",
                    kMaxMapKeyframes, kMaxMapPoints, kMaxMapLines));
  auto timing = [&](const char* name, const MsHistogram& h, bool last) {
    add(std::snprintf(buf, sizeof(buf), "    \"%s\": {\"mean\": %.3f, \"p50\": %.3f, \"p99\": %.3f, \"max\": %.3f}%s\n",
                      name, h.mean(), h.percentile(50), h.percentile(99), h.max(), last ? "" : ","));
  };
  out += "  \"ms_per_frame\": {\n";
  timing("total", r.total_ms, false);
  timing("extract", r.extract_ms, false);
  timing("track", r.track_ms, false);
  timing("map", r.map_ms, true);
  out += "  },\n";
  add(std::snprintf(buf, sizeof(buf), "  \"line_samples\": %d, \"lines\": %s,\n",
                    options.system.odometry.extractor.line_samples,
                    options.system.odometry.tracker.use_lines ? "true" : "false"));
  out += "  \"rss_checkpoints\": [";
  for (std::size_t i = 0; i < r.rss.size(); ++i) {
    add(std::snprintf(buf, sizeof(buf), "%s{\"frame\": %ld, \"peak_kib\": %ld, \"current_kib\": %ld}",
                      i ? ", " : "", r.rss[i].frame, r.rss[i].peak_rss_kib, r.rss[i].current_rss_kib));
  }
  out += "],\n";
  if (ate_rmse_m >= 0) {
    add(std::snprintf(buf, sizeof(buf), "  \"ate_rmse_m\": %.6f\n}\n", ate_rmse_m));
  } else {
    out += "  \"ate_rmse_m\": null\n}\n";
  }
  return out;
}


void enableKinectNoise(SynthOptions* options) {
  options->depth_noise = true;
  options->depth_noise_k = 0.0014;
  options->depth_edge_holes = true;
  options->pixel_noise_sigma = 1.0;
}

Status openNoisySynthetic(const std::string& spec, std::unique_ptr<SyntheticSource>* out) {
  const std::string prefix = "synth:";
  if (spec.rfind(prefix, 0) != 0) return Status::Error(spec + ": not a synth:PRESET[:SEED[:FRAMES]] source");
  std::vector<std::string> parts;
  std::size_t start = prefix.size();
  for (std::size_t colon; (colon = spec.find(':', start)) != std::string::npos; start = colon + 1) {
    parts.push_back(spec.substr(start, colon - start));
  }
  parts.push_back(spec.substr(start));
  if (parts.size() > 3 || parts[0].empty()) return Status::Error(spec + ": expected synth:PRESET[:SEED[:FRAMES]]");
  SynthOptions options;
  options.preset = parts[0];
  auto parse_count = [&spec](const std::string& text, long* value) {
    char* end = nullptr;
    *value = std::strtol(text.c_str(), &end, 10);
    if (text.empty() || *end != '\0' || *value < 0) return Status::Error(spec + ": '" + text + "' is not a count");
    return Status::Ok();
  };
  long value = 0;
  if (parts.size() > 1) {
    PLUMB_RETURN_IF_ERROR(parse_count(parts[1], &value));
    options.seed = uint64_t(value);
  }
  if (parts.size() > 2) {
    PLUMB_RETURN_IF_ERROR(parse_count(parts[2], &value));
    options.frames = int(value);
  }
  enableKinectNoise(&options);
  PLUMB_RETURN_IF_ERROR(validate(options).withContext(spec));
  return SyntheticSource::create(options, out).withContext(spec);
}

std::vector<StampedPose> syntheticGroundTruth(const SyntheticScene& scene, long frames) {
  std::vector<StampedPose> gt;
  gt.reserve(std::size_t(std::max(0L, frames)));
  for (long i = 0; i < frames; ++i) {
    StampedPose p;
    p.timestamp = scene.timestamp(int(i));
    p.T_world_cam = scene.T_world_cam(int(i));
    gt.push_back(p);
  }
  return gt;
}

Status ateRmse(const std::vector<StampedPose>& ground_truth, const std::vector<StampedPose>& estimate,
               double* rmse_m) {
  AteResult ate;
  PLUMB_RETURN_IF_ERROR(evaluateAte(ground_truth, estimate, AteOptions{}, &ate));
  *rmse_m = ate.translation_m.rmse;
  return Status::Ok();
}

void setLineOptions(int line_samples, bool use_lines, SystemOptions* options) {
  options->odometry.extractor.line_samples = line_samples;
  // A 3D line fit needs min_line_inliers samples (default 3): with fewer samples per line, every
  // sample must be an inlier, or N = 1, 2 would silently mean "no lines".
  options->odometry.extractor.min_line_inliers =
      std::max(1, std::min(options->odometry.extractor.min_line_inliers, line_samples));
  // No samples means nothing for lines to contribute: the points-only system.
  options->odometry.tracker.use_lines = use_lines && line_samples > 0;
}

}  // namespace plumb::tools

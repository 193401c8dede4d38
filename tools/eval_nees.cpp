#include "tools/eval_nees.h"

#include <cstdio>

#include "runtime/json_text.h"

namespace plumb::tools {
namespace {

struct Named {
  const char* key;
  const char* title;
  const NeesStatistics& s;
};

std::string perDof(const NeesStatistics& s) { return s.count ? runtime::jsonNumber(s.mean_per_dof) : "null"; }

}  // namespace

Status evaluateNeesFiles(const std::vector<StampedPose>& ground_truth, const std::vector<StampedPose>& estimate,
                         const std::vector<std::string>& covariance_paths, NeesResult* out) {
  StampedPose anchor;
  anchor.valid = false;
  for (const StampedPose& p : estimate) {
    if (p.valid) {
      anchor = p;
      break;
    }
  }
  CovarianceFile merged;
  for (const std::string& path : covariance_paths) {
    CovarianceFile file;
    PLUMB_RETURN_IF_ERROR(readCovarianceFile(path, &file).withContext("reading covariance"));
    const bool tracked = file.kind == CovarianceFileKind::kTracked;
    if ((tracked && !merged.frames.empty()) || (!tracked && !merged.keyframes.empty()))
      return Status::Error(path + ": a second " + (tracked ? "tracked" : "keyframe") + " covariance file");
    if (tracked) merged.frames = std::move(file.frames);
    else merged.keyframes = std::move(file.keyframes);
  }
  return evaluateNees(ground_truth, merged, anchor, NeesOptions{}, out);
}

void printNeesText(const NeesResult& r) {
  const Named rows[] = {{"keyframe_relative", "keyframe-to-keyframe (BA joint marginal)", r.keyframe_relative},
                        {"tracked_world", "tracked pose in the world (as MAVLink sends)", r.tracked_world},
                        {"frame_motion", "frame-to-frame motion (MAVLink velocity x dt)", r.frame_motion}};
  std::printf("NEES per dof (1 = calibrated; 6-dof error vs its covariance; inside = share within the 95%% ellipsoid)\n");
  for (const Named& n : rows) {
    const NeesStatistics& s = n.s;
    if (s.count == 0) {
      std::printf("  %-46s no samples (%zu stamps without ground truth)\n", n.title, s.skipped_no_truth);
      continue;
    }
    std::printf("  %-46s %.3f (median %.3f, translation %.3f, rotation %.3f), inside 95%%: %.1f%%, n %zu\n", n.title,
                s.mean_per_dof, s.median_per_dof, s.translation_mean_per_dof, s.rotation_mean_per_dof,
                100.0 * s.inside_95, s.count);
    std::printf("  %-46s error RMS %.4f m %.3f deg, claimed sigma RMS %.4f m %.3f deg\n", "", s.rmse_translation_m,
                s.rmse_rotation_deg, s.rms_sigma_translation_m, s.rms_sigma_rotation_deg);
  }
}

std::string neesJsonMembers(const NeesResult& r) {
  using runtime::jsonNumber;
  const Named rows[] = {{"keyframe_relative", "", r.keyframe_relative},
                        {"tracked_world", "", r.tracked_world},
                        {"frame_motion", "", r.frame_motion}};
  std::string per_dof = " \"nees_per_dof\": {", detail = " \"nees\": {";
  for (std::size_t i = 0; i < 3; ++i) {
    const NeesStatistics& s = rows[i].s;
    const std::string sep = i ? ", " : "";
    per_dof += sep + "\"" + rows[i].key + "\": " + perDof(s);
    char text[768];
    std::snprintf(text, sizeof(text),
                  "\"%s\": {\"count\": %zu, \"skipped_no_truth\": %zu, \"mean_per_dof\": %s, \"median_per_dof\": %s, "
                  "\"translation_mean_per_dof\": %s, \"rotation_mean_per_dof\": %s, \"inside_95\": %s, "
                  "\"rmse_translation_m\": %s, \"rmse_rotation_deg\": %s, \"rms_sigma_translation_m\": %s, "
                  "\"rms_sigma_rotation_deg\": %s}",
                  rows[i].key, s.count, s.skipped_no_truth, perDof(s).c_str(),
                  s.count ? jsonNumber(s.median_per_dof).c_str() : "null",
                  s.count ? jsonNumber(s.translation_mean_per_dof).c_str() : "null",
                  s.count ? jsonNumber(s.rotation_mean_per_dof).c_str() : "null",
                  s.count ? jsonNumber(s.inside_95).c_str() : "null", jsonNumber(s.rmse_translation_m).c_str(),
                  jsonNumber(s.rmse_rotation_deg).c_str(), jsonNumber(s.rms_sigma_translation_m).c_str(),
                  jsonNumber(s.rms_sigma_rotation_deg).c_str());
    detail += sep + text;
  }
  return per_dof + "},\n" + detail + "}";
}

}  // namespace plumb::tools

#include "pipeline/run/loop_audit_json.h"

#include <algorithm>
#include <cinttypes>
#include <cstdio>

#include "runtime/json_text.h"

namespace plumb {

namespace {

template <typename... Values>
void append(std::string* out, const char* format, Values... values) {
  char buf[256];
  const int n = std::snprintf(buf, sizeof(buf), format, values...);
  if (n > 0) out->append(buf, std::size_t(std::min<int>(n, int(sizeof(buf)) - 1)));
}

std::string number(double value, const char* format = "%.6f") { return runtime::jsonNumber(value, format); }

}  // namespace

std::string loopAuditJson(const LoopRunResult& loop) {
  std::string out = "  \"loop_audit\": {";
  append(&out, "\"entries_dropped\": %" PRIu64 ", \"keyframes_dropped\": %" PRIu64 ",\n    \"keyframes\": [",
         loop.audit_entries_dropped, loop.audit_keyframes_dropped);
  for (std::size_t i = 0; i < loop.audit_keyframes.size(); ++i) {
    const loop::LoopAuditKeyframe& k = loop.audit_keyframes[i];
    append(&out, "%s[%u, %s]", i ? ", " : "", k.id, number(k.timestamp_s).c_str());
  }
  out += "],\n    \"candidates\": [";
  for (std::size_t i = 0; i < loop.audit.size(); ++i) {
    const loop::LoopAuditEntry& e = loop.audit[i];
    out += i ? ",\n      {" : "\n      {";
    append(&out, "\"query_id\": %u, \"query_t\": %s, \"candidate_id\": %u, \"candidate_t\": %s, ", e.query_id,
           number(e.query_timestamp_s).c_str(), e.candidate_id, number(e.candidate_timestamp_s).c_str());
    append(&out, "\"score\": %s, \"matches\": %d, \"ransac_inliers\": %d, \"point_inliers\": %d, ",
           number(e.place_score, "%.4f").c_str(), e.matches, e.ransac_inliers, e.point_inliers);
    append(&out, "\"line_matches\": %d, \"line_sample_inliers\": %d, ", e.line_matches, e.line_sample_inliers);
    append(&out, "\"unreliable_features\": %d, \"max_leverage\": %s, ", e.unreliable_features,
           number(e.max_leverage, "%.3f").c_str());
    append(&out, "\"correction_m\": %s, \"correction_deg\": %s, \"chi2\": %s, \"outcome\": %s",
           number(e.correction_m, "%.5f").c_str(), number(e.correction_deg, "%.4f").c_str(),
           number(e.chi2, "%.4g").c_str(), runtime::jsonString(loop::toString(e.outcome)).c_str());
    if (e.outcome == loop::LoopRejection::kNone || e.outcome == loop::LoopRejection::kRolledBack) {
      append(&out, ", \"context_matches\": %d, \"context_cost_before\": %s, \"context_cost_after\": %s",
             e.context_matches, number(e.context_cost_before, "%.1f").c_str(), number(e.context_cost_after, "%.1f").c_str());
    }
    if (e.covariance.trace() > 0) {
      // Rotation row-major, then translation (the map file's pose layout); the 21 upper-triangle
      // entries of the covariance row by row (the --covariance file's layout).
      out += ",\n       \"T_candidate_query\": [";
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) append(&out, "%s%.12g", r + c ? ", " : "", e.T_candidate_query.linear()(r, c));
      for (int r = 0; r < 3; ++r) append(&out, ", %.12g", e.T_candidate_query.translation()(r));
      out += "], \"covariance\": [";
      bool first = true;
      for (int r = 0; r < 6; ++r)
        for (int c = r; c < 6; ++c) {
          append(&out, "%s%.9g", first ? "" : ", ", e.covariance(r, c));
          first = false;
        }
      out += "]";
    }
    out += "}";
  }
  out += "]}";
  return out;
}

}  // namespace plumb

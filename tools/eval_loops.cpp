#include "tools/eval_loops.h"

#include <cstdio>

#include "drivers/trajectory/loop_grading.h"
#include "runtime/json_text.h"

namespace plumb::tools {

int evalLoops(const std::vector<StampedPose>& ground_truth, const std::string& stats_path, bool json) {
  LoopAuditFile audit;
  const Status st = readLoopAudit(stats_path, &audit);
  if (!st.ok()) {
    std::fprintf(stderr, "plumb eval: %s\n", st.message().c_str());
    return 1;
  }
  const LoopGradingOptions options;
  const LoopGrading g = gradeLoops(ground_truth, audit, options);
  using runtime::jsonNumber;
  if (json) {
    std::printf("{\"stats\": %s, \"verified\": %zu, \"accepted\": %zu, \"graded\": %zu, \"correct\": %zu, "
                "\"within_5cm_2deg\": %zu, \"precision\": %s,\n \"revisit_keyframes\": %zu, \"revisits\": %zu, \"revisits_recalled\": %zu, "
                "\"recall\": %s,\n \"loops\": [",
                runtime::jsonString(stats_path).c_str(), g.verified, g.accepted, g.graded, g.correct, g.within_distance,
                jsonNumber(g.precision(), "%.4f").c_str(), g.revisit_keyframes, g.revisits, g.revisits_recalled,
                jsonNumber(g.recall(), "%.4f").c_str());
    for (std::size_t i = 0; i < g.loops.size(); ++i) {
      const GradedLoop& l = g.loops[i];
      std::printf("%s\n  {\"query_id\": %u, \"query_t\": %.6f, \"candidate_id\": %u, \"candidate_t\": %.6f, "
                  "\"ground_truth\": %s, \"error_m\": %s, \"error_deg\": %s, \"error_sigmas\": %s, \"baseline_m\": %s, "
                  "\"baseline_deg\": %s, \"correct\": %s}",
                  i ? "," : "", l.query_id, l.query_t, l.candidate_id, l.candidate_t,
                  l.has_ground_truth ? "true" : "false",
                  l.has_ground_truth ? jsonNumber(l.error_m, "%.5f").c_str() : "null",
                  l.has_ground_truth ? jsonNumber(l.error_deg, "%.4f").c_str() : "null",
                  l.has_ground_truth ? jsonNumber(l.error_sigmas, "%.3f").c_str() : "null",
                  l.has_ground_truth ? jsonNumber(l.baseline_m, "%.4f").c_str() : "null",
                  l.has_ground_truth ? jsonNumber(l.baseline_deg, "%.2f").c_str() : "null",
                  l.correct ? "true" : "false");
    }
    std::printf("]}\n");
    return 0;
  }
  std::printf("loops: %zu verified, %zu accepted, %zu with ground truth at both ends\n", g.verified, g.accepted,
              g.graded);
  for (const GradedLoop& l : g.loops) {
    if (!l.has_ground_truth) {
      std::printf("  query %u (t %.3f) -> candidate %u (t %.3f): no ground truth\n", l.query_id, l.query_t,
                  l.candidate_id, l.candidate_t);
      continue;
    }
    std::printf("  query %u (t %.3f) -> candidate %u (t %.3f): error %.4f m, %.3f deg, %.2f sigma  %s"
                "  (views %.3f m, %.1f deg apart)\n",
                l.query_id, l.query_t, l.candidate_id, l.candidate_t, l.error_m, l.error_deg, l.error_sigmas,
                l.correct ? "correct" : "WRONG", l.baseline_m, l.baseline_deg);
  }
  std::printf("loop precision %.1f %% (%zu of %zu correct: <= %.0f cm, <= %.0f deg, chi2 <= %.2f)\n",
              100.0 * g.precision(), g.correct, g.graded, options.max_error_m * 100, options.max_error_deg,
              options.max_chi2);
  std::printf("within %.0f cm and %.0f deg (the covariance aside): %zu of %zu\n", options.max_error_m * 100,
              options.max_error_deg, g.within_distance, g.graded);
  std::printf("revisit recall %.1f %% (%zu of %zu revisits, %zu revisit keyframes)\n", 100.0 * g.recall(),
              g.revisits_recalled, g.revisits, g.revisit_keyframes);
  return 0;
}

}  // namespace plumb::tools

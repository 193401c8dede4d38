#include "drivers/trajectory/loop_grading.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

#include "platform/input_file.h"
#include "runtime/json_reader.h"
#include "solver/se3.h"

namespace plumb {

namespace {

Status numberArray(const runtime::JsonValue* v, std::size_t n, const std::string& what, double* out) {
  if (v == nullptr || v->type != runtime::JsonValue::Type::kArray || v->items.size() != n)
    return Status::Error(what + " must be an array of " + std::to_string(n) + " numbers");
  for (std::size_t i = 0; i < n; ++i) {
    if (!v->items[i].isNumber()) return Status::Error(what + " must be an array of " + std::to_string(n) + " numbers");
    out[i] = v->items[i].number;
  }
  return Status::Ok();
}

Status numberMember(const runtime::JsonValue& object, const char* name, const std::string& where, double* out) {
  const runtime::JsonValue* v = object.find(name);
  if (v == nullptr || !v->isNumber()) return Status::Error(where + ": \"" + name + "\" missing or not a number");
  *out = v->number;
  return Status::Ok();
}

Status readCandidate(const runtime::JsonValue& c, const std::string& where, AuditedLoop* out) {
  if (c.type != runtime::JsonValue::Type::kObject) return Status::Error(where + " is not an object");
  double q = 0, k = 0;
  PLUMB_RETURN_IF_ERROR(numberMember(c, "query_id", where, &q));
  PLUMB_RETURN_IF_ERROR(numberMember(c, "candidate_id", where, &k));
  PLUMB_RETURN_IF_ERROR(numberMember(c, "query_t", where, &out->query_t));
  PLUMB_RETURN_IF_ERROR(numberMember(c, "candidate_t", where, &out->candidate_t));
  out->query_id = uint32_t(q);
  out->candidate_id = uint32_t(k);
  const runtime::JsonValue* outcome = c.find("outcome");
  if (outcome == nullptr || !outcome->isString()) return Status::Error(where + ": \"outcome\" missing");
  out->outcome = outcome->string;
  const runtime::JsonValue* T = c.find("T_candidate_query");
  out->has_constraint = T != nullptr;
  if (!out->has_constraint) {
    if (out->outcome == "accepted") return Status::Error(where + ": an accepted loop without T_candidate_query");
    return Status::Ok();
  }
  double t[12], cov[21];
  PLUMB_RETURN_IF_ERROR(numberArray(T, 12, where + ": T_candidate_query", t));
  PLUMB_RETURN_IF_ERROR(numberArray(c.find("covariance"), 21, where + ": covariance", cov));
  Eigen::Matrix3d R;
  R << t[0], t[1], t[2], t[3], t[4], t[5], t[6], t[7], t[8];
  out->T_candidate_query = Eigen::Isometry3d::Identity();
  out->T_candidate_query.linear() = R;
  out->T_candidate_query.translation() = Eigen::Vector3d(t[9], t[10], t[11]);
  int i = 0;
  for (int r = 0; r < 6; ++r)
    for (int col = r; col < 6; ++col) out->covariance(r, col) = out->covariance(col, r) = cov[i++];
  return Status::Ok();
}

double viewAngleDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  const double cosine = a.linear().col(2).dot(b.linear().col(2));
  return std::acos(std::clamp(cosine, -1.0, 1.0)) * kDegreesPerRadian;
}

}  // namespace

Status readLoopAudit(const std::string& stats_path, LoopAuditFile* out) {
  std::string text;
  PLUMB_RETURN_IF_ERROR(readInputFile(stats_path, kMaxTextInputBytes, "statistics file", &text));
  runtime::JsonValue root;
  Status st = runtime::parseJson(text, &root);
  if (!st.ok()) return st.withContext("reading " + stats_path);
  const runtime::JsonValue* audit = root.find("loop_audit");
  if (audit == nullptr || audit->type != runtime::JsonValue::Type::kObject) {
    return Status::Error(stats_path +
                         " has no \"loop_audit\" object (written by `plumb run --stats` with loop closing on)");
  }
  out->keyframes.clear();
  out->candidates.clear();
  const runtime::JsonValue* keyframes = audit->find("keyframes");
  const runtime::JsonValue* candidates = audit->find("candidates");
  if (keyframes == nullptr || keyframes->type != runtime::JsonValue::Type::kArray || candidates == nullptr ||
      candidates->type != runtime::JsonValue::Type::kArray) {
    return Status::Error(stats_path + ": loop_audit needs the arrays \"keyframes\" and \"candidates\"");
  }
  for (std::size_t i = 0; i < keyframes->items.size(); ++i) {
    double pair[2];
    PLUMB_RETURN_IF_ERROR(
        numberArray(&keyframes->items[i], 2, stats_path + ": loop_audit.keyframes[" + std::to_string(i) + "]", pair));
    out->keyframes.emplace_back(uint32_t(pair[0]), pair[1]);
  }
  for (std::size_t i = 0; i < candidates->items.size(); ++i) {
    AuditedLoop loop;
    PLUMB_RETURN_IF_ERROR(readCandidate(candidates->items[i],
                                        stats_path + ": loop_audit.candidates[" + std::to_string(i) + "]", &loop));
    out->candidates.push_back(loop);
  }
  return Status::Ok();
}

bool groundTruthAt(const std::vector<StampedPose>& gt, double t, double max_gap_s, Eigen::Isometry3d* T) {
  const auto after = std::lower_bound(gt.begin(), gt.end(), t,
                                      [](const StampedPose& p, double time) { return p.timestamp < time; });
  const StampedPose* next = after != gt.end() && after->valid ? &*after : nullptr;
  const StampedPose* previous = after != gt.begin() && std::prev(after)->valid ? &*std::prev(after) : nullptr;
  if (next != nullptr && std::abs(next->timestamp - t) < 1e-9) {
    *T = next->T_world_cam;
    return true;
  }
  if (next != nullptr && previous != nullptr && next->timestamp - previous->timestamp <= max_gap_s) {
    const double a = (t - previous->timestamp) / (next->timestamp - previous->timestamp);
    const Eigen::Quaterniond q0(previous->T_world_cam.linear()), q1(next->T_world_cam.linear());
    *T = Eigen::Isometry3d::Identity();
    T->linear() = q0.slerp(a, q1).normalized().toRotationMatrix();
    T->translation() = (1 - a) * previous->T_world_cam.translation() + a * next->T_world_cam.translation();
    return true;
  }
  const StampedPose* nearest = nullptr;
  for (const StampedPose* p : {previous, next}) {
    if (p != nullptr && std::abs(p->timestamp - t) < 0.02 &&
        (nearest == nullptr || std::abs(p->timestamp - t) < std::abs(nearest->timestamp - t)))
      nearest = p;
  }
  if (nearest == nullptr) return false;
  *T = nearest->T_world_cam;
  return true;
}

LoopGrading gradeLoops(const std::vector<StampedPose>& gt, const LoopAuditFile& audit,
                       const LoopGradingOptions& o) {
  LoopGrading g;
  g.verified = audit.candidates.size();
  std::vector<uint32_t> correct_queries;
  for (const AuditedLoop& c : audit.candidates) {
    if (c.outcome != "accepted") continue;
    ++g.accepted;
    GradedLoop l;
    l.query_id = c.query_id;
    l.candidate_id = c.candidate_id;
    l.query_t = c.query_t;
    l.candidate_t = c.candidate_t;
    Eigen::Isometry3d G_q, G_c;
    l.has_ground_truth =
        groundTruthAt(gt, c.query_t, o.max_gt_gap_s, &G_q) && groundTruthAt(gt, c.candidate_t, o.max_gt_gap_s, &G_c);
    if (l.has_ground_truth) {
      const Eigen::Isometry3d G_candidate_query = G_c.inverse() * G_q;
      l.baseline_m = G_candidate_query.translation().norm();
      l.baseline_deg = Eigen::AngleAxisd(G_candidate_query.linear()).angle() * kDegreesPerRadian;
      // T_query_candidate = Z^-1 is perturbed on the left: true = exp(e) Z^-1, e = log(G_q^-1 G_c Z).
      const Eigen::Isometry3d E = G_q.inverse() * G_c * c.T_candidate_query;
      const Vector6d e = logSE3(E);
      l.error_m = E.translation().norm();
      l.error_deg = Eigen::AngleAxisd(E.linear()).angle() * kDegreesPerRadian;
      const Eigen::LDLT<Matrix6d> ldlt(c.covariance);
      const double chi2 = ldlt.info() == Eigen::Success ? e.dot(ldlt.solve(e)) : INFINITY;
      l.error_sigmas = std::sqrt(std::max(0.0, chi2));
      const bool close = l.error_m <= o.max_error_m && l.error_deg <= o.max_error_deg;
      l.correct = close && chi2 <= o.max_chi2;
      g.within_distance += close ? 1 : 0;
      ++g.graded;
      if (l.correct) {
        ++g.correct;
        correct_queries.push_back(c.query_id);
      }
    }
    g.loops.push_back(l);
  }

  // Revisits: keyframes with ground truth, in id order.
  struct Kf {
    uint32_t id;
    double t;
    Eigen::Isometry3d G;
  };
  std::vector<Kf> kfs;
  for (const auto& [id, t] : audit.keyframes) {
    Eigen::Isometry3d G;
    if (groundTruthAt(gt, t, o.max_gt_gap_s, &G)) kfs.push_back(Kf{id, t, G});
  }
  std::sort(kfs.begin(), kfs.end(), [](const Kf& a, const Kf& b) { return a.id < b.id; });
  bool in_revisit = false;
  double revisit_start_t = 0;
  bool recalled = false;
  auto close = [&] {
    if (in_revisit) {
      ++g.revisits;
      g.revisits_recalled += recalled ? 1 : 0;
    }
    in_revisit = false;
    recalled = false;
  };
  for (std::size_t i = 0; i < kfs.size(); ++i) {
    const Kf& q = kfs[i];
    // The newest keyframe old enough to be a candidate of q: the ground truth up to its time.
    double boundary_t = -INFINITY;
    for (std::size_t j = 0; j < i; ++j)
      if (int64_t(kfs[j].id) <= int64_t(q.id) - o.min_age_keyframes) boundary_t = std::max(boundary_t, kfs[j].t);
    bool revisit = false;
    for (const StampedPose& p : gt) {
      if (p.timestamp > boundary_t) break;  // sorted by time
      if (!p.valid) continue;
      revisit = (p.T_world_cam.translation() - q.G.translation()).norm() <= o.revisit_distance_m &&
                viewAngleDeg(p.T_world_cam, q.G) <= o.revisit_angle_deg;
      if (revisit) break;
    }
    if (!revisit) {
      close();
      continue;
    }
    ++g.revisit_keyframes;
    if (in_revisit && q.t - revisit_start_t > o.revisit_span_s) close();
    if (!in_revisit) {
      in_revisit = true;
      revisit_start_t = q.t;
    }
    recalled = recalled || std::find(correct_queries.begin(), correct_queries.end(), q.id) != correct_queries.end();
  }
  close();
  return g;
}

}  // namespace plumb

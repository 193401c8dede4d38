#include "pipeline/loop/loop_closer.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "solver/pose_covariance.h"
#include "solver/rigid_fit.h"
#include "solver/se3.h"
#include "solver/se3_jacobians.h"

namespace plumb::loop {

namespace {

KeyframeDatabaseOptions databaseOptions(const LoopCloserOptions& o) {
  KeyframeDatabaseOptions d;
  d.max_keyframes = o.capacity + 1;  // the newest is inserted before the oldest is culled
  d.max_point_descriptors = int(kMaxLoopPoints);
  d.max_line_descriptors = int(kMaxLoopLines);
  d.max_postings = (o.capacity + 1) * int(kMaxLoopPoints + kMaxLoopLines);  // every descriptor its own word
  d.bits_per_word = o.bits_per_word;
  return d;
}

Matrix6d diagonalCovariance(double sigma_t, double sigma_r) {
  Matrix6d c = Matrix6d::Zero();
  c.diagonal() << sigma_t * sigma_t, sigma_t * sigma_t, sigma_t * sigma_t, sigma_r * sigma_r,
      sigma_r * sigma_r, sigma_r * sigma_r;
  return c;
}

Matrix6d inverseSpd(const Matrix6d& m) {
  const Eigen::LDLT<Matrix6d> ldlt(m);
  return ldlt.solve(Matrix6d::Identity());
}

double poseDistance(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  const double dt = (a.translation() - b.translation()).norm();
  const double dr = Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
  return dt + 0.5 * dr;  // 0.5 m per radian: a 10 cm step and a 11 deg turn weigh the same
}

}  // namespace

LoopCloser::LoopCloser(const CameraIntrinsics& camera, const NoiseModelOptions& noise,
                       const LoopCloserOptions& options)
    : options_(options),
      verifier_(camera, noise, options.verifier),
      context_check_(camera, options.context),
      database_(databaseOptions(options)),
      graph_(options.capacity + 1, options.capacity + 1 + options.max_loop_edges),
      records_(std::size_t(options.capacity + 1)),
      nodes_(std::size_t(options.capacity + 1)) {
  // Odometry chain + loop edges: natural order, factor storage reserved here (no allocation by
  // operator new in later analyses).
  graph_.reserveChainWithExtraEdges(options.max_loop_edges);
  free_slots_.reserve(std::size_t(options.capacity + 1));
  for (int s = options.capacity; s >= 0; --s) free_slots_.push_back(s);
  order_.reserve(std::size_t(options.capacity + 1));
  poses_before_.resize(std::size_t(options.capacity + 1));
  fit_graph_.resize(std::size_t(options.capacity + 1));
  fit_mapping_.resize(std::size_t(options.capacity + 1));
  loop_edges_.reserve(std::size_t(options.max_loop_edges));
  residency_.add(records_.data(), records_.size() * sizeof(LoopCandidate));
  database_.queueReservedMemory(&residency_);
  for (const PoseGraph::ReservedRange& range : graph_.reservedRanges()) residency_.add(range.data, range.bytes);
}

LoopCloser::~LoopCloser() = default;

std::size_t LoopCloser::memoryBytesFor(const LoopCloserOptions& o) {
  const std::size_t slots = std::size_t(o.capacity + 1);
  // Pose graph: nodes (~2 isometries), edges (isometry + 6x6 + kernel), blocks; H's pattern and
  // the factor (allocated in analyze(), bounded by the structure) are not counted here.
  const std::size_t graph = slots * 300 + (slots + std::size_t(o.max_loop_edges)) * 450;
  // reserveChainWithExtraEdges(): H and the factor's value + index arrays (12 bytes an entry).
  const std::size_t edges = slots + 1 + std::size_t(o.max_loop_edges);
  const std::size_t sparse =
      12 * (21 * slots + 36 * edges +
            std::size_t(PoseGraph::chainFactorEntries(int(slots), o.max_loop_edges)));
  return sizeof(LoopCloser) + slots * (sizeof(LoopCandidate) + sizeof(Node) + 2 * sizeof(int)) +
         std::size_t(o.max_loop_edges) * sizeof(LoopEdge) +
         KeyframeDatabase::memoryBytesFor(databaseOptions(o)) + graph + sparse + sizeof(LoopVerifier) +
         LoopVerifier::scratchBytes() +
         slots * sizeof(Eigen::Isometry3d) +  // poses before an optimisation (rollback)
         2 * slots * sizeof(Eigen::Vector3d) +  // the real-time anchor's fit (outputFit)
         LoopContextCheck::scratchBytes() +
         LoopAudit::kDefaultMaxEntries * sizeof(LoopAuditEntry) +
         LoopAudit::kDefaultMaxKeyframes * sizeof(LoopAuditKeyframe);
}

std::size_t LoopCloser::memoryBytes() const { return memoryBytesFor(options_); }

int LoopCloser::findPosition(uint32_t id) const {
  // order_ is sorted by id: binary search.
  int lo = 0, hi = int(order_.size()) - 1;
  while (lo <= hi) {
    const int mid = (lo + hi) / 2;
    const uint32_t m = nodes_[std::size_t(order_[std::size_t(mid)])].id;
    if (m == id) return mid;
    if (m < id)
      lo = mid + 1;
    else
      hi = mid - 1;
  }
  return -1;
}

bool LoopCloser::pose(uint32_t keyframe_id, Eigen::Isometry3d* T_world_cam) const {
  const int p = findPosition(keyframe_id);
  if (p < 0) return false;
  *T_world_cam = nodes_[std::size_t(order_[std::size_t(p)])].T_world_cam;
  return true;
}

bool LoopCloser::finalPose(uint32_t keyframe_id, Eigen::Isometry3d* T_world_cam, uint64_t* epoch) const {
  const int p = findPosition(keyframe_id);
  if (p < 0) return false;
  const Node& n = nodes_[std::size_t(order_[std::size_t(p)])];
  if (!n.has_final) return false;
  *T_world_cam = n.T_world_final;
  *epoch = n.final_epoch;
  return true;
}

Matrix6d LoopCloser::edgeCovariance(bool new_segment, const Matrix6d& covariance, bool covariance_valid) {
  if (new_segment)
    return diagonalCovariance(options_.segment_translation_sigma_m, options_.segment_rotation_sigma_rad);
  if (covariance_valid) {
    // Finite, SPD and within a physical bound (a degenerate BA marginal is refused, counted).
    if (publishablePoseCovariance(covariance, options_.max_edge_translation_sigma_m, options_.max_edge_rotation_sigma_rad)) {
      return 0.5 * (covariance + covariance.transpose()) +
             diagonalCovariance(options_.odometry_floor_translation_sigma_m, options_.odometry_floor_rotation_sigma_rad);
    }
    ++stats_.edge_covariances_refused;
  }
  return diagonalCovariance(options_.default_translation_sigma_m, options_.default_rotation_sigma_rad);
}

void LoopCloser::addNode(const LoopKeyframe& r, int slot) {
  Node& n = nodes_[std::size_t(slot)];
  n = Node{};
  n.id = r.id;
  n.timestamp_s = r.timestamp_s;
  n.T_world_record = r.T_world_cam;
  n.T_world_mapping = r.T_world_cam;
  if (order_.empty()) {
    n.T_world_cam = r.T_world_cam;  // the graph's frame is the first keyframe's mapping frame
  } else {
    const Node& previous = nodes_[std::size_t(order_.back())];
    n.has_edge = true;
    if (!r.new_segment && r.previous_id == previous.id) {
      n.previous_map_id = r.previous_id;
      n.T_previous_this = r.T_previous_this;
      n.edge_covariance = edgeCovariance(r.new_segment, r.covariance, r.covariance_valid);
    } else {
      // A new segment, or the previous keyframe's record never arrived (full ring): the relative
      // pose of the two records as the mapping side had them, with the weak segment covariance.
      n.T_previous_this = previous.T_world_mapping.inverse() * r.T_world_cam;
      n.edge_covariance =
          diagonalCovariance(options_.segment_translation_sigma_m, options_.segment_rotation_sigma_rad);
    }
    n.edge_length_m = n.T_previous_this.translation().norm();
    n.T_world_cam = previous.T_world_cam * n.T_previous_this;
  }
  order_.push_back(slot);
}

void LoopCloser::refreshWindowEdges(const LoopKeyframe& r) {
  // An odometry edge between two keyframes still in the local map is their relative pose as the
  // BA that inserted the later one left it; every local BA since refined both poses. The record
  // carries the local map as the newest BA left it: those edges become the relative of the two
  // current poses (a relative pose: the same whatever loop corrections moved the map rigidly).
  // Their covariances stay (the BA that made the edge). Edges of keyframes that left the local
  // map are the final poses' (keyframeFinal) and are not touched.
  for (const LoopWindowPose& w : r.window) {
    const int p = findPosition(w.id);
    if (p <= 0) continue;
    Node& n = nodes_[std::size_t(order_[std::size_t(p)])];
    if (!n.has_edge || n.has_final || n.previous_map_id == 0) continue;
    if (nodes_[std::size_t(order_[std::size_t(p - 1)])].id != n.previous_map_id) continue;
    for (const LoopWindowPose& previous : r.window) {
      if (previous.id != n.previous_map_id) continue;
      n.T_previous_this = previous.T_world_cam.inverse() * w.T_world_cam;
      n.edge_length_m = n.T_previous_this.translation().norm();
      break;
    }
  }
}

bool LoopCloser::addKeyframe(const LoopKeyframe& record) {
  ++stats_.keyframes;
  if (!order_.empty() && record.id <= nodes_[std::size_t(order_.back())].id) return false;  // out of order
  if (free_slots_.empty()) return false;  // cannot happen: culling keeps one slot free
  const int slot = free_slots_.back();
  free_slots_.pop_back();
  makeLoopCandidate(record, &records_[std::size_t(slot)]);
  const LoopKeyframe& r = record;
  addNode(r, slot);
  refreshWindowEdges(r);
  const int query_position = int(order_.size()) - 1;
  audit_.addKeyframe(r.id, r.timestamp_s);

  bool accepted = false;
  // Query before inserting: a keyframe never finds itself.
  const PlaceDescriptors descriptors{r.point_descriptors.data(), r.point_descriptors.size(),
                                     r.line_descriptors.data(), r.line_descriptors.size()};
  // Early consistency: the query also returns the keyframes up to `lookahead` ids younger than the
  // age bound, for the consistency count only (detect() verifies none of them), and keyframes
  // start querying that much earlier, so the first keyframes old enough to be candidates can be
  // consistent already.
  const int lookahead = options_.early_consistency ? std::max(0, options_.min_consistent - 1) : 0;
  if (int64_t(r.id) > int64_t(options_.min_age_keyframes) - lookahead) {
    ++stats_.queries;
    PlaceQueryOptions q;
    q.max_results = std::size_t(std::min<int>(options_.candidates + lookahead, int(kMaxPlaceCandidates)));
    q.max_candidate_id = uint64_t(int64_t(r.id) - int64_t(options_.min_age_keyframes) + lookahead);
    q.min_score = options_.min_candidate_score;
    database_.query(descriptors, q, &candidates_);
    const std::size_t before = stats_.loops_accepted;
    detect(r, query_position);
    accepted = stats_.loops_accepted > before;
  } else {
    groups_.clear();
  }
  (void)database_.insert(r.id, descriptors);  // sized for capacity + 1: cannot fail
  if (accepted) {
    for (std::size_t p = 0; p < order_.size(); ++p) poses_before_[p] = nodes_[std::size_t(order_[p])].T_world_cam;
    optimise();
    accepted = confirmNewestLoop();
    if (accepted) {
      // Which loop made the correction, for viewers: the edge just accepted, at the optimised pose.
      const LoopEdge& edge = loop_edges_.back();
      correction_.loop_candidate_id = edge.candidate_id;
      if (!pose(edge.candidate_id, &correction_.T_world_candidate)) correction_.loop_candidate_id = 0;
    }
  }
  if (int(order_.size()) > options_.capacity) cullOne();
  stats_.graph_nodes = order_.size();
  stats_.peak_graph_nodes = std::max<uint64_t>(stats_.peak_graph_nodes, order_.size());
  stats_.loop_edges = loop_edges_.size();
  return accepted;
}

void LoopCloser::detect(const LoopKeyframe& query_record, int query_position) {
  const Node& query = nodes_[std::size_t(order_[std::size_t(query_position)])];
  // Consistency: each candidate inherits the count of the previous query's nearest group.
  new_groups_.clear();
  for (const PlaceCandidate& c : candidates_) {
    int count = 1;
    for (const Group& g : groups_) {
      const int64_t d = int64_t(g.id) - int64_t(c.keyframe_id);
      if (std::llabs(d) <= options_.consistency_neighbourhood) count = std::max(count, g.count + 1);
    }
    (void)new_groups_.push_back(Group{uint32_t(c.keyframe_id), count, float(c.score)});
  }
  groups_ = new_groups_;
  if (cooldown_ > 0) {
    --cooldown_;
    return;
  }
  int verified = 0;
  for (const Group& g : groups_) {  // candidates_ order: best score first
    if (g.count < options_.min_consistent || verified >= options_.max_verifications) continue;
    if (int64_t(g.id) > int64_t(query.id) - int64_t(options_.min_age_keyframes)) continue;  // consistency only
    ++stats_.consistent_candidates;
    const int candidate_position = findPosition(g.id);
    if (candidate_position < 0) continue;  // culled meanwhile
    ++verified;
    ++stats_.verifications;
    const LoopCandidate& candidate = records_[std::size_t(order_[std::size_t(candidate_position)])];
    LoopMeasurement m = verifier_.verify(query_record, candidate);
    LoopAuditEntry entry;
    entry.query_id = query.id;
    entry.candidate_id = candidate.id;
    entry.query_timestamp_s = query.timestamp_s;
    entry.candidate_timestamp_s = nodes_[std::size_t(order_[std::size_t(candidate_position)])].timestamp_s;
    entry.place_score = g.score;
    entry.matches = m.matches;
    entry.ransac_inliers = m.ransac_inliers;
    entry.point_inliers = m.refined_inliers;
    entry.line_matches = m.line_matches;
    entry.line_sample_inliers = m.line_inliers;
    entry.unreliable_features = m.unreliable_features;
    entry.max_leverage = m.max_leverage;
    entry.correction_m = entry.correction_deg = entry.chi2 = std::numeric_limits<double>::quiet_NaN();
    const Matrix6d covariance =
        0.5 * (m.covariance + m.covariance.transpose()) +
        diagonalCovariance(options_.floor_translation_sigma_m, options_.floor_rotation_sigma_rad);
    if (m.accepted() && !certain(covariance)) m.rejection = LoopRejection::kUncertain;
    if (m.accepted()) {
      entry.T_candidate_query = m.T_candidate_query;
      entry.covariance = covariance;
      entry.chi2 = plausibilityChi2(candidate_position, query_position, m, &entry.correction_m, &entry.correction_deg);
      if (!(entry.chi2 <= options_.plausibility_chi2)) m.rejection = LoopRejection::kImplausible;
    }
    entry.outcome = m.rejection;
    LoopAuditEntry* stored = audit_.add(entry);
    if (!m.accepted()) {
      ++stats_.rejected[int(m.rejection)];
      continue;
    }
    pending_ = PendingLoop{};
    pending_.active = true;
    pending_.candidate_id = candidate.id;
    pending_.audit = stored;
    if (loop_edges_.size() >= std::size_t(options_.max_loop_edges)) {
      pending_.evicted_edge = true;
      pending_.evicted = loop_edges_.front();
      loop_edges_.erase(loop_edges_.begin());
    }
    loop_edges_.push_back(LoopEdge{candidate.id, query.id, m.T_candidate_query, inverseSpd(covariance)});
    ++stats_.loops_accepted;
    cooldown_ = options_.cooldown_keyframes;
    return;  // one loop per keyframe
  }
}

Matrix6d LoopCloser::odometryCovariance(int candidate_position, int query_position, bool drift_prior) const {
  const Node& q = nodes_[std::size_t(order_[std::size_t(query_position)])];
  const Eigen::Isometry3d T_cam_q_world = q.T_world_cam.inverse();
  Matrix6d sigma = Matrix6d::Zero();
  for (int p = candidate_position + 1; p <= query_position; ++p) {
    const Node& j = nodes_[std::size_t(order_[std::size_t(p)])];
    const double len = drift_prior ? j.edge_length_m : 0.0;
    const Matrix6d edge = j.edge_covariance + diagonalCovariance(options_.drift_translation_per_m * len,
                                                                 options_.drift_rotation_rad_per_m * len);
    const Matrix6d Ad = adjointSE3(T_cam_q_world * j.T_world_cam);  // T_q_j
    sigma += Ad * edge * Ad.transpose();
  }
  return sigma;
}

double LoopCloser::plausibilityChi2(int candidate_position, int query_position, const LoopMeasurement& m,
                                    double* correction_m, double* correction_deg) const {
  const Node& c = nodes_[std::size_t(order_[std::size_t(candidate_position)])];
  const Node& q = nodes_[std::size_t(order_[std::size_t(query_position)])];
  const Eigen::Isometry3d T_cam_q_world = q.T_world_cam.inverse();
  const Matrix6d sigma = 0.5 * (m.covariance + m.covariance.transpose()) +
                        odometryCovariance(candidate_position, query_position, true) +
                        diagonalCovariance(options_.floor_translation_sigma_m, options_.floor_rotation_sigma_rad);
  const Vector6d e = poseGraphEdgeError(m.T_candidate_query, c.T_world_cam.inverse(), T_cam_q_world);
  // The query's current pose seen from where the loop puts it: how far the correction moves it.
  const Eigen::Isometry3d E = m.T_candidate_query.inverse() * c.T_world_cam.inverse() * q.T_world_cam;
  *correction_m = E.translation().norm();
  *correction_deg = Eigen::AngleAxisd(E.linear()).angle() * 180.0 / M_PI;
  const double chi2 = e.dot(Eigen::LDLT<Matrix6d>(sigma).solve(e));
  return std::isfinite(chi2) ? chi2 : std::numeric_limits<double>::infinity();
}

void LoopCloser::keyframeFinal(uint32_t keyframe_id, const Eigen::Isometry3d& T_world_cam,
                               const Matrix6d& covariance, bool covariance_valid, uint64_t epoch) {
  const int p = findPosition(keyframe_id);
  if (p < 0) return;
  Node& n = nodes_[std::size_t(order_[std::size_t(p)])];
  n.has_final = true;
  n.final_epoch = epoch;
  n.T_world_final = T_world_cam;
  if (p == 0 || n.previous_map_id == 0) return;
  const Node& previous = nodes_[std::size_t(order_[std::size_t(p - 1)])];
  if (previous.id != n.previous_map_id || !previous.has_final || previous.final_epoch != epoch) return;
  n.T_previous_this = previous.T_world_final.inverse() * T_world_cam;
  n.edge_length_m = n.T_previous_this.translation().norm();
  n.edge_covariance = edgeCovariance(false, covariance, covariance_valid);
  edges_changed_ = true;
  ++stats_.edges_refined;
}

void LoopCloser::finalOptimise() {
  if (edges_changed_ && !order_.empty()) optimise();
}

void LoopCloser::optimise() {
  edges_changed_ = false;
  const auto start = std::chrono::steady_clock::now();
  graph_.clear();
  for (std::size_t p = 0; p < order_.size(); ++p) {
    const Node& n = nodes_[std::size_t(order_[p])];
    (void)graph_.addNode(int64_t(n.id), n.T_world_cam.inverse(), p == 0);
    if (p > 0 && n.has_edge) {
      (void)graph_.addEdge(int(p) - 1, int(p), n.T_previous_this, inverseSpd(n.edge_covariance));
    }
  }
  const RobustKernel huber{RobustKernelType::kHuber, options_.loop_huber_delta};
  for (const LoopEdge& e : loop_edges_) {
    const int i = findPosition(e.candidate_id), j = findPosition(e.query_id);
    if (i < 0 || j < 0) continue;
    (void)graph_.addEdge(i, j, e.T_candidate_query, e.information, huber);
  }
  const PoseGraphSummary summary = graph_.optimize(options_.graph);
  if (summary.ok()) {
    for (std::size_t p = 0; p < order_.size(); ++p) {
      nodes_[std::size_t(order_[p])].T_world_cam = graph_.pose(int(p)).inverse();
    }
  }
  // The real-time correction (docs/LOOP.md "What the robot receives"). What was output is fixed:
  // the query must go where it belongs in the frame of that output. kOutputFit: the graph's
  // optimum of the query (the loop and every odometry edge and earlier loop) moved by the rigid
  // fit of the graph's keyframes onto their mapping-frame poses, i.e. into the frame the output as
  // a whole is in. kCandidate (and the fallback): where the loop says it is relative to the
  // candidate's pose when it was made (its record's; its final local-map pose may already carry
  // corrections made while it was still in the local map): the frame of that one keyframe, whose
  // own drift then shifts everything after (the map's first keyframe has none, the rest of the
  // lap has the lap's: office_loop seed 2's `--out` went 1.24x of no loops, and a second loop to
  // a drifted keyframe moved it back). The graph's optimum itself, in its first keyframe's gauge,
  // is the optimised trajectory's.
  const Node& query = nodes_[std::size_t(order_.back())];
  correction_.keyframe_id = query.id;
  correction_.T_world_cam = query.T_world_cam;
  if (!loop_edges_.empty() && loop_edges_.back().query_id == query.id) {
    const int c = findPosition(loop_edges_.back().candidate_id);
    if (c >= 0) {
      const Node& candidate = nodes_[std::size_t(order_[std::size_t(c)])];
      const LoopEdge& edge = loop_edges_.back();
      Eigen::Isometry3d T_world_loop = candidate.T_world_mapping * edge.T_candidate_query;
      if (options_.realtime_anchor == RealtimeAnchor::kOutputFit) {
        Eigen::Isometry3d T_mapping_graph;
        if (outputFit(&T_mapping_graph)) T_world_loop = T_mapping_graph * query.T_world_cam;
      }
      correction_.T_world_cam = T_world_loop;
      if (options_.fuse_realtime_correction) {
        // Minimum-variance update of the query's pose as the robot has it (T_odo: its record) with
        // the loop (T_loop): d = log(T_cw(loop) T_cw(odo)^-1) is the full correction, in the
        // query frame; the odometry from the candidate to the query is uncertain by S_odo (the
        // calibrated edge covariances along the graph), the loop by S_loop, so the query moves by
        // K d, K = S_odo (S_odo + S_loop)^-1: all the way when the loop is far more certain than
        // the drift (K ~ I), halfway when both are alike, instead of jumping by the loop's own
        // error where there was little drift to remove.
        const Matrix6d S_odo = odometryCovariance(c, int(order_.size()) - 1, false);
        const Matrix6d S_loop = inverseSpd(edge.information);
        const Matrix6d K = S_odo * inverseSpd(S_odo + S_loop);
        const Eigen::Isometry3d T_cw_odo = query.T_world_mapping.inverse();
        const Vector6d d = logSE3(T_world_loop.inverse() * query.T_world_mapping);
        const Vector6d step = K * d;
        if (step.allFinite()) correction_.T_world_cam = applyLeftIncrement(step, T_cw_odo).inverse();
      }
    }
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  ++stats_.optimisations;
  stats_.optimisation_ms_total += ms;
  stats_.optimisation_ms_max = std::max(stats_.optimisation_ms_max, ms);
}

bool LoopCloser::outputFit(Eigen::Isometry3d* T_mapping_graph) {
  // Every keyframe before the query: its optimised position (graph) against where the mapping
  // frame had it (what was output around it). The query itself is what is being placed.
  const int n = int(order_.size()) - 1;
  if (n < 3) return false;
  for (int p = 0; p < n; ++p) {
    const Node& node = nodes_[std::size_t(order_[std::size_t(p)])];
    fit_graph_[std::size_t(p)] = node.T_world_cam.translation();
    fit_mapping_[std::size_t(p)] = node.T_world_mapping.translation();
  }
  // A fit over keyframes along a line leaves the rotation about it free: refuse (the candidate
  // anchor is used).
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int p = 0; p < n; ++p) mean += fit_graph_[std::size_t(p)];
  mean /= n;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int p = 0; p < n; ++p) {
    const Eigen::Vector3d d = fit_graph_[std::size_t(p)] - mean;
    scatter += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> spread(scatter / n, Eigen::EigenvaluesOnly);
  if (spread.info() != Eigen::Success || !(spread.eigenvalues()(1) >= options_.min_fit_spread_m * options_.min_fit_spread_m))
    return false;
  return rigidFitKabsch(fit_graph_.data(), fit_mapping_.data(), nullptr, n, T_mapping_graph);
}

bool LoopCloser::certain(const Matrix6d& covariance) const {
  return poseSigmasWithin(covariance, options_.max_loop_sigma_m, options_.max_loop_sigma_rad);
}

bool LoopCloser::confirmNewestLoop() {
  const bool was_pending = pending_.active;
  pending_.active = false;
  if (!was_pending || !options_.context_check) return was_pending;
  const int query_position = int(order_.size()) - 1;
  const int candidate_position = findPosition(pending_.candidate_id);
  if (candidate_position < 0) return true;
  // Query side: the query and its predecessors; candidate side: the candidate, then its
  // neighbours alternately after and before it. Both as the graph had them and as optimised.
  LoopContextSide query, candidate;
  auto add = [&](LoopContextSide* side, int p) {
    if (side->count >= 8) return;
    const int slot = order_[std::size_t(p)];
    side->records[side->count] = &records_[std::size_t(slot)];
    side->T_world_before[side->count] = poses_before_[std::size_t(p)];
    side->T_world_after[side->count] = nodes_[std::size_t(slot)].T_world_cam;
    ++side->count;
  };
  add(&query, query_position);
  for (int k = 1; k <= options_.context.query_neighbours && query_position - k > candidate_position; ++k)
    add(&query, query_position - k);
  add(&candidate, candidate_position);
  for (int k = 1; k <= options_.context.candidate_neighbours; ++k) {
    if (candidate_position + k < query_position - options_.context.query_neighbours) add(&candidate, candidate_position + k);
    if (candidate_position - k >= 0) add(&candidate, candidate_position - k);
  }
  const LoopContextResult r = context_check_.evaluate(query, candidate);
  if (pending_.audit != nullptr) {
    pending_.audit->context_matches = r.matches;
    pending_.audit->context_cost_before = r.cost_before;
    pending_.audit->context_cost_after = r.cost_after;
  }
  if (context_check_.accepts(r)) return true;
  // Roll back: the graph as it was, the loop edge gone (and the one it evicted back), nothing
  // published, counted as a rejection.
  for (std::size_t p = 0; p < order_.size(); ++p) nodes_[std::size_t(order_[p])].T_world_cam = poses_before_[p];
  loop_edges_.pop_back();
  if (pending_.evicted_edge) loop_edges_.insert(loop_edges_.begin(), pending_.evicted);
  if (pending_.audit != nullptr) pending_.audit->outcome = LoopRejection::kRolledBack;
  --stats_.loops_accepted;
  ++stats_.rejected[int(LoopRejection::kRolledBack)];
  cooldown_ = 0;
  return false;
}

void LoopCloser::cullOne() {
  // Interior nodes only: not the first (the gauge), not the newest (the next record links to it).
  int victim = -1;
  double best = 0;
  for (int pass = 0; pass < 2 && victim < 0; ++pass) {
    for (int p = 1; p + 1 < int(order_.size()); ++p) {
      const Node& n = nodes_[std::size_t(order_[std::size_t(p)])];
      const Node& next = nodes_[std::size_t(order_[std::size_t(p + 1)])];
      if (pass == 0) {  // first pass: keep keyframes that anchor a loop edge
        bool anchored = false;
        for (const LoopEdge& e : loop_edges_) anchored |= e.candidate_id == n.id || e.query_id == n.id;
        if (anchored) continue;
      }
      const Node& previous = nodes_[std::size_t(order_[std::size_t(p - 1)])];
      const double score =
          poseDistance(previous.T_world_cam, n.T_world_cam) + poseDistance(n.T_world_cam, next.T_world_cam);
      if (victim < 0 || score < best) {
        victim = p;
        best = score;
      }
    }
  }
  if (victim < 0) return;
  const int slot = order_[std::size_t(victim)];
  Node& r = nodes_[std::size_t(slot)];
  Node& next = nodes_[std::size_t(order_[std::size_t(victim + 1)])];
  // previous -> r -> next becomes previous -> next: T_p_n = T_p_r T_r_n; r's uncertainty (in r's
  // frame) reaches next through Ad(T_n_r).
  const Matrix6d Ad = adjointSE3(next.T_previous_this.inverse());
  next.edge_covariance = Ad * r.edge_covariance * Ad.transpose() + next.edge_covariance;
  next.T_previous_this = r.T_previous_this * next.T_previous_this;
  next.edge_length_m += r.edge_length_m;
  next.has_edge = next.has_edge && r.has_edge;
  for (std::size_t i = 0; i < loop_edges_.size();) {
    if (loop_edges_[i].candidate_id == r.id || loop_edges_[i].query_id == r.id) {
      loop_edges_.erase(loop_edges_.begin() + long(i));
    } else {
      ++i;
    }
  }
  (void)database_.remove(r.id);
  order_.erase(order_.begin() + victim);
  free_slots_.push_back(slot);
  ++stats_.culled;
}

}  // namespace plumb::loop

#pragma once
// LoopCloser: loop detection, verification and pose-graph optimisation over a FIXED number of
// keyframe records (docs/LOOP.md). One owner thread (the loop stage).
//
// addKeyframe(record), for each keyframe the mapping side inserted, in id order:
//   1. graph: a node for the keyframe, linked to the previous node by an odometry edge
//      T_previous_this weighted by its calibrated covariance from local BA's joint marginal
//      (docs/UNCERTAINTY.md; + a numerical floor only), or by a default
//      information when BA gave none; a new map segment is linked by a weak edge. Edges between
//      keyframes still in the local map follow it: each record's window (the local map as its BA
//      left it) refreshes them; keyframeFinal() replaces them when they leave it.
//   2. detection: KeyframeDatabase query, candidates older than min_age_keyframes (outside the
//      local window); a candidate must be consistent over min_consistent consecutive queries
//      (each query had a candidate within consistency_neighbourhood ids of it).
//   3. verification: LoopVerifier (ORB + LBD matching, 3D-3D RANSAC, point + line refinement).
//   4. plausibility: the correction the loop implies at this keyframe, e = log(Z^-1 T_c T_q^-1),
//      must be explained by the odometry uncertainty accumulated from the candidate to the query:
//      e^T (sum_j Ad(T_q_j) (S_j + drift_j) Ad(T_q_j)^T + S_loop)^-1 e <= plausibility_chi2.
//      (S_j: edge covariances; drift_j: a prior proportional to the distance travelled.) Repeated
//      texture typically implies a jump of a whole module that this test refuses.
//   5. a loop edge (Huber kernel), pose-graph LM (solver/pose_graph.h), and a MapCorrection for
//      the query keyframe for the mapping side: its pose as the robot had it moved towards the
//      graph's optimum of it in the frame of everything output so far (realtime_anchor), by the
//      minimum-variance share of the correction (fuse_realtime_correction; docs/LOOP.md "What
//      the robot receives").
// Lifelong bound: when `capacity` records are held, the most redundant keyframe (smallest distance
// to its two graph neighbours; not the first, the newest, or one with a loop edge) is culled: its two
// odometry edges are composed into one (covariances propagated), it leaves the database.
//
// MEMORY: everything is allocated in the constructor. The large stores (candidate records,
// database postings, the pose graph's H and factor) are not written there: makeResidentStep()
// makes them resident a slice at a time (the loop stage calls it after each keyframe but the
// first), so the first pose does not wait for ~8 MiB of page faults, and after a few keyframes the
// resident set does not grow as the graph fills (memoryBytes(); docs/LOOP.md "Memory";
// platform/memory_residency.h). addKeyframe() makes no operator-new allocation; when a loop is accepted,
// PoseGraph::analyze() (the graph is rebuilt: culling changes its structure) still makes a few
// malloc calls (Eigen's outer-index arrays).
#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

#include "pipeline/loop/keyframe_database.h"
#include "pipeline/loop/loop_audit.h"
#include "pipeline/loop/loop_context_check.h"
#include "pipeline/loop/loop_keyframe.h"
#include "pipeline/loop/loop_verifier.h"
#include "pipeline/loop/saved_map.h"
#include "pipeline/odometry/map_capacities.h"
#include "pipeline/odometry/map_correction.h"
#include "solver/pose_graph.h"

namespace plumb::loop {

// Where the real-time correction puts the query keyframe before the minimum-variance share of
// fuse_realtime_correction is taken (docs/LOOP.md "What the robot receives"):
//   kCandidate  the candidate's pose as the robot had it composed with the loop's relative pose:
//               the robot's frame becomes that one keyframe's (with its drift, zero at the map's
//               start: the extreme of a lap's drift), and a later loop to another keyframe moves
//               it again into that keyframe's;
//   kOutputFit  the graph's optimised query pose in the frame of everything output so far: the
//               least-squares rigid fit of the graph's keyframe positions onto their positions in
//               the mapping frame (what was output around them), i.e. the frame a rigid
//               alignment of the output finds. Falls back to kCandidate when fewer than 3
//               keyframes precede the query or they lie along a line (min_fit_spread_m).
enum class RealtimeAnchor : int { kCandidate = 0, kOutputFit = 1 };

struct LoopCloserOptions {
  int capacity = 128;          // keyframe records = database entries = graph nodes (docs/LOOP.md "Memory")
  int max_loop_edges = 24;     // the oldest loop edge is forgotten when full
  // candidate id <= query id - this: outside the local map (kMaxMapKeyframes = 32 keyframes), whose
  // own BA already ties the query to everything younger. (It was 40: with ~37 keyframes per lap
  // of a room, that left only places visited EARLIER on the previous lap as candidates, i.e.
  // long-baseline loops seen from 1-2 m away, instead of the revisit itself.)
  int min_age_keyframes = int(kMaxMapKeyframes) + 1;
  int candidates = 10;         // database results per query
  double min_candidate_score = 0.02;
  int consistency_neighbourhood = 4;  // candidate ids this close name the same place
  int min_consistent = 3;             // consecutive queries agreeing, this one included
  // The consistency count can be met at the age bound: each query also lists the min_consistent - 1
  // keyframes just younger than `min_age_keyframes` (never verified: counted only), and queries
  // start that many keyframes earlier. Without it the first two keyframes old enough to have a
  // candidate can never be consistent, and a room lap of ~34 keyframes (office_loop) lost exactly
  // its closest revisit (docs/LOOP.md "Recall").
  bool early_consistency = true;
  int max_verifications = 3;          // consistent candidates verified per query, best score first
  int cooldown_keyframes = 3;         // after an accepted loop, keyframes not searched
  LoopVerifierOptions verifier;
  int bits_per_word = kDefaultWordBits;
  // Odometry edge covariance when local BA gave none, or gave one beyond the bounds below.
  double default_translation_sigma_m = 0.02;
  double default_rotation_sigma_rad = 0.01;
  // A BA relative covariance whose largest translation or rotation sigma exceeds these is refused
  // as an edge weight (the default above is used and `edge_covariances_refused` counts it): a
  // near-singular window can give an SPD covariance of 1e9 m^2, and the graph's LM then stops with
  // that almost weightless edge unsatisfied, leaving a rigid step in the optimised chain even
  // without a loop (docs/UNCERTAINTY.md "Variance components in local BA: tried, not shipped").
  // Consecutive keyframes are centimetres apart: a 1 m or 0.5 rad sigma is no measurement.
  double max_edge_translation_sigma_m = 1.0;
  double max_edge_rotation_sigma_rad = 0.5;
  // Added to BA's covariance of an odometry edge: numerical only (every edge's information stays
  // finite), 30x and 20x below the 3 mm / 0.002 rad model floor these edges had before. BA's
  // relative covariances are calibrated (variance factor, correlation factor, rolling-shutter
  // model error: docs/UNCERTAINTY.md), so they already carry the model errors that make odometry
  // drift; a model floor on top dominated them 3-10x, weighted every edge alike whatever BA knew,
  // and a loop's correction then went into the edges that had no error (docs/LOOP.md "Why a
  // correct loop made the optimised trajectory worse").
  double odometry_floor_translation_sigma_m = 1e-4;
  double odometry_floor_rotation_sigma_rad = 1e-4;
  // Added to the loop edge's covariance and to the plausibility test's sum: numerical only, like
  // the odometry edges'. The verifier's covariance is calibrated (both ends' noise propagated,
  // variance factor, rolling-shutter error of both images: docs/LOOP.md "The loop constraint's
  // covariance"); until issue 20 it held the candidate's points exact and a 3 mm / 0.002 rad model
  // floor stood in for what it missed.
  double floor_translation_sigma_m = 1e-4;
  double floor_rotation_sigma_rad = 1e-4;
  // The first keyframe of a new map segment: the tracker restarted at its last known pose.
  double segment_translation_sigma_m = 1.0;
  double segment_rotation_sigma_rad = 0.5;
  // Plausibility (step 4): drift prior per metre travelled and the chi-square bound (6 dof,
  // 99.9%: 22.46).
  double drift_translation_per_m = 0.03;
  double drift_rotation_rad_per_m = 0.02;
  double plausibility_chi2 = 22.46;
  // Certainty of the measurement itself: a loop whose verification pins the relative pose no
  // better than this (1 sigma along its worst translation axis / rotation axis, from the
  // refinement's covariance) is rejected as `uncertain`: a view of the same place from metres
  // away, dominated by far points, measures the loop by centimetres at best, and a correction
  // that uncertain can only add noise to drift of the same size.
  double max_loop_sigma_m = 0.03;
  double max_loop_sigma_rad = 0.0175;  // 1 deg
  // The real-time correction (docs/LOOP.md "What the robot receives"): true, the query keyframe
  // moves by the minimum-variance share K = S_odo (S_odo + S_loop)^-1 of the correction the loop
  // implies (S_odo: the calibrated odometry covariance from the candidate to the query, no drift
  // prior); false, all the way to where the loop puts it.
  bool fuse_realtime_correction = true;
  // kOutputFit since issue 20's office study: anchored to the candidate, a correct loop to the
  // map's first keyframe made synth:office_loop seed 2's `--out` 1.24x of no loops.
  RealtimeAnchor realtime_anchor = RealtimeAnchor::kOutputFit;
  // kOutputFit needs the keyframes before the query spread this far (RMS, second principal axis)
  // across their line, else the fit's rotation about it is free.
  double min_fit_spread_m = 0.05;
  double loop_huber_delta = 2.8;  // whitened (sqrt chi-square); ~95% of a 6-dof inlier's chi
  // Do no harm: after the graph is optimised with a new loop, the covisible landmarks of the
  // keyframes around both sides must be explained at least as well as before, or the loop is
  // rolled back (loop_context_check.h). Off: every verified, plausible loop is applied.
  bool context_check = true;
  LoopContextCheckOptions context;
  PoseGraphOptions graph;
};

struct LoopStats {
  uint64_t keyframes = 0;  // records added
  uint64_t queries = 0;
  uint64_t consistent_candidates = 0;
  uint64_t verifications = 0;
  uint64_t loops_accepted = 0;
  uint64_t rejected[kNumLoopRejections] = {};  // by LoopRejection (index 0 unused)
  uint64_t culled = 0;
  uint64_t edges_refined = 0;  // odometry edges replaced by final local-map poses
  uint64_t edge_covariances_refused = 0;  // BA covariances beyond the options' bounds (default used)
  uint64_t optimisations = 0;
  double optimisation_ms_total = 0;
  double optimisation_ms_max = 0;
  uint64_t loop_edges = 0;   // held now
  uint64_t graph_nodes = 0;  // held now
  uint64_t peak_graph_nodes = 0;
};

class LoopCloser {
 public:
  LoopCloser(const CameraIntrinsics& camera, const NoiseModelOptions& noise,
             const LoopCloserOptions& options);
  ~LoopCloser();
  LoopCloser(const LoopCloser&) = delete;
  LoopCloser& operator=(const LoopCloser&) = delete;

  // Adds the record (copied) and runs detection; true when a loop was accepted and the graph
  // optimised: correction() then holds the query keyframe's new pose.
  bool addKeyframe(const LoopKeyframe& record);
  const MapCorrection& correction() const { return correction_; }

  // A keyframe's FINAL local-map pose and covariance (it left the local map), `epoch` = loop
  // corrections the mapping side had applied then. When its graph predecessor is the keyframe
  // before it in the map and got its final pose in the same epoch, the odometry edge between them
  // is replaced by the relative of the two final poses (BA refined them many times since the
  // records were made). Takes effect at the next optimisation (finalOptimise() at the end of a run).
  void keyframeFinal(uint32_t keyframe_id, const Eigen::Isometry3d& T_world_cam, const Matrix6d& covariance,
                     bool covariance_valid, uint64_t epoch);
  // End of a run: optimises once more if edges changed since the last optimisation (without any
  // loop edge this simply re-chains the refined odometry).
  void finalOptimise();

  // Map files (docs/LOOP.md "Map files", loop_closer_map.cpp). exportMap: every record with its
  // graph node and the loop edges (map->camera is the caller's). restoreMap: into an EMPTY closer,
  // before any addKeyframe; the database is rebuilt from the records' descriptors. Refused (nothing
  // changed) when the closer is not empty, the map exceeds capacity or max_loop_edges, or a
  // covariance / information matrix is not positive definite.
  void exportMap(SavedMap* map) const;
  Status restoreMap(const SavedMap& map);

  // The graph's current pose of a keyframe (optimised after a loop); false if not in the graph.
  bool pose(uint32_t keyframe_id, Eigen::Isometry3d* T_world_cam) const;
  // Its final local-map pose and the loop epoch it was reported in (keyframeFinal); false if the
  // keyframe is not in the graph or never left the local map.
  bool finalPose(uint32_t keyframe_id, Eigen::Isometry3d* T_world_cam, uint64_t* epoch) const;
  std::size_t size() const { return order_.size(); }
  std::size_t capacity() const { return std::size_t(options_.capacity); }
  const LoopStats& stats() const { return stats_; }
  // Every candidate that reached verification and what became of it (loop_audit.h).
  const LoopAudit& audit() const { return audit_; }
  const LoopCloserOptions& options() const { return options_; }
  // Ids in the graph, ascending.
  uint32_t idAt(std::size_t i) const { return nodes_[std::size_t(order_[i])].id; }
  std::size_t memoryBytes() const;
  static std::size_t memoryBytesFor(const LoopCloserOptions& options);
  // Makes up to max_bytes more of the reserved stores resident (contents unchanged). Returns the
  // bytes still pending; 0 once all are resident.
  std::size_t makeResidentStep(std::size_t max_bytes) { return residency_.step(max_bytes); }
  std::size_t residentPendingBytes() const { return residency_.pendingBytes(); }

 private:
  struct Node {
    uint32_t id = 0;
    double timestamp_s = 0;  // the record's (0 for a keyframe loaded from a map file)
    Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();     // graph estimate
    Eigen::Isometry3d T_world_record = Eigen::Isometry3d::Identity();  // the record's, at creation
    // Where THIS run's mapping frame had the keyframe: the record's pose for a keyframe of this run,
    // the loaded (optimised) pose for one of a loaded map, which the run relocalizes against. It
    // links the mapping frame to the graph (a new segment's first node, the real-time correction's
    // anchor); T_world_record is kept as written, for the map file.
    Eigen::Isometry3d T_world_mapping = Eigen::Isometry3d::Identity();
    bool has_edge = false;                                          // from the previous node in order_
    Eigen::Isometry3d T_previous_this = Eigen::Isometry3d::Identity();
    Matrix6d edge_covariance = Matrix6d::Identity();  // of this node, previous held fixed
    double edge_length_m = 0;                         // distance travelled along the edge
    uint32_t previous_map_id = 0;  // the record's previous keyframe in the map (0: none / segment)
    bool has_final = false;        // keyframeFinal() seen
    uint64_t final_epoch = 0;
    Eigen::Isometry3d T_world_final = Eigen::Isometry3d::Identity();
  };
  // A loop edge is what a map file stores of it (saved_map.h): one type, copied as is.
  using LoopEdge = SavedLoopEdge;
  struct Group {
    uint32_t id = 0;
    int count = 0;
    float score = 0;
  };

  int findPosition(uint32_t id) const;  // index into order_, -1 if absent
  void addNode(const LoopKeyframe& record, int slot);
  void cullOne();
  void detect(const LoopKeyframe& query_record, int query_position);
  // The plausibility chi-square of the loop (step 4) and the correction it implies.
  // Covariance of the query's pose relative to the candidate accumulated along the odometry edges
  // between them, in the query frame; with `drift_prior` each edge adds the plausibility test's
  // prior proportional to its length.
  Matrix6d odometryCovariance(int candidate_position, int query_position, bool drift_prior) const;
  double plausibilityChi2(int candidate_position, int query_position, const LoopMeasurement& m,
                          double* correction_m, double* correction_deg) const;
  void optimise();
  // The odometry edges between keyframes of the record's local-map window, from its current poses.
  void refreshWindowEdges(const LoopKeyframe& record);
  // After optimise() with the loop just accepted: the do-no-harm check; false = rolled back.
  bool confirmNewestLoop();
  // The loop edge's covariance is within max_loop_sigma_m / max_loop_sigma_rad.
  bool certain(const Matrix6d& covariance) const;
  // kOutputFit: the rigid motion taking the graph's positions of the keyframes before the query
  // onto their mapping-frame positions (least squares); false when too few or along a line.
  bool outputFit(Eigen::Isometry3d* T_mapping_graph);
  Matrix6d edgeCovariance(bool new_segment, const Matrix6d& covariance, bool covariance_valid);

  LoopCloserOptions options_;
  LoopVerifier verifier_;
  LoopContextCheck context_check_;
  KeyframeDatabase database_;
  PoseGraph graph_;
  // By slot: what verification needs of each keyframe as a candidate, for the full capacity. From
  // kernel zero pages (all-zero bytes = LoopCandidate{}, and makeLoopCandidate assigns a slot
  // whole): resident as used or as makeResidentStep() reaches it.
  std::vector<LoopCandidate, ZeroPageAllocator<LoopCandidate>> records_;
  std::vector<Node> nodes_;                  // by slot
  std::vector<int> free_slots_;
  std::vector<int> order_;  // slots by ascending keyframe id
  std::vector<LoopEdge> loop_edges_;
  FixedVector<Group, kMaxPlaceCandidates> groups_, new_groups_;
  PlaceCandidates candidates_;
  int cooldown_ = 0;
  // The loop accepted by detect() for this keyframe, until confirmNewestLoop() keeps or undoes it.
  struct PendingLoop {
    bool active = false;
    uint32_t candidate_id = 0;
    bool evicted_edge = false;  // the oldest loop edge was forgotten to make room
    LoopEdge evicted;
    LoopAuditEntry* audit = nullptr;  // may be null (audit full)
  };
  PendingLoop pending_;
  std::vector<Eigen::Vector3d> fit_graph_, fit_mapping_;  // outputFit() scratch, by position
  std::vector<Eigen::Isometry3d> poses_before_;  // by position in order_, before the optimisation
  bool edges_changed_ = false;  // since the last optimisation
  MapCorrection correction_;
  LoopStats stats_;
  LoopAudit audit_;
  ResidencyQueue residency_;  // records_, the database's postings, the graph's reserved arrays
};

}  // namespace plumb::loop

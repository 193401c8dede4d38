// LoopCloser <-> SavedMap (docs/LOOP.md "Map files").
#include <algorithm>
#include <string>

#include <Eigen/Cholesky>

#include "pipeline/loop/loop_closer.h"

namespace plumb::loop {

namespace {

bool positiveDefinite(const Matrix6d& m) {
  if (!m.allFinite()) return false;
  const Eigen::LLT<Matrix6d> llt(0.5 * (m + m.transpose()));
  return llt.info() == Eigen::Success;
}

// The closer keeps only a keyframe's LoopCandidate (what verification and relocalization read):
// the record written to a map file carries those features and their octaves; the query-only
// fields (pixel, u_right, the 2D line) are written as zero and the record's header from the graph
// node. (A map written before the octaves were kept has zeros there: octave 0, the finest noise.)
void recordOfCandidate(const LoopCandidate& c, LoopKeyframe* r) {
  r->clearFeatures();
  r->id = c.id;
  for (std::size_t k = 0; k < c.num_points; ++k) {
    LoopPoint p;
    p.P_cam = c.P_cam[k];
    p.octave = c.point_octave[k];
    (void)r->points.push_back(p);
    (void)r->point_descriptors.push_back(c.point_descriptors[k]);
  }
  for (std::size_t k = 0; k < c.num_lines; ++k) {
    LoopLine line;
    line.num_samples = c.num_samples[k];
    line.octave = c.line_octave[k];
    for (std::size_t s = 0; s < line.num_samples; ++s) line.samples_cam[s] = c.samples_cam[c.first_sample[k] + s];
    (void)r->lines.push_back(line);
    (void)r->line_descriptors.push_back(c.line_descriptors[k]);
  }
}

}  // namespace

void LoopCloser::exportMap(SavedMap* map) const {
  map->keyframes.clear();
  map->keyframes.reserve(order_.size());
  for (int slot : order_) {
    const Node& n = nodes_[std::size_t(slot)];
    auto k = std::make_unique<SavedKeyframe>();
    recordOfCandidate(records_[std::size_t(slot)], &k->record);
    k->record.T_world_cam = n.T_world_record;
    k->record.previous_id = n.previous_map_id;
    k->record.T_previous_this = n.T_previous_this;
    k->T_world_cam = n.T_world_cam;
    k->has_edge = n.has_edge;
    k->T_previous_this = n.T_previous_this;
    k->edge_covariance = n.edge_covariance;
    k->edge_length_m = n.edge_length_m;
    k->previous_map_id = n.previous_map_id;
    map->keyframes.push_back(std::move(k));
  }
  map->loop_edges = loop_edges_;
}

Status LoopCloser::restoreMap(const SavedMap& map) {
  if (!order_.empty()) return Status::Error("the loop closer already holds keyframes: a map loads into an empty one");
  if (map.keyframes.size() > std::size_t(options_.capacity)) {
    return Status::Error("the map holds " + std::to_string(map.keyframes.size()) +
                         " keyframes, more than the loop closer's capacity " + std::to_string(options_.capacity));
  }
  if (map.loop_edges.size() > std::size_t(options_.max_loop_edges)) {
    return Status::Error("the map holds " + std::to_string(map.loop_edges.size()) +
                         " loop edges, more than the loop closer keeps (" + std::to_string(options_.max_loop_edges) + ")");
  }
  uint32_t previous_id = 0;
  for (std::size_t i = 0; i < map.keyframes.size(); ++i) {
    const SavedKeyframe& k = *map.keyframes[i];
    if (k.record.id <= previous_id) return Status::Error("map keyframe ids are not strictly ascending");
    previous_id = k.record.id;
    if (i > 0 && k.has_edge && !positiveDefinite(k.edge_covariance)) {
      return Status::Error("map keyframe " + std::to_string(k.record.id) + ": edge covariance is not positive definite");
    }
    if (k.record.points.size() != k.record.point_descriptors.size() ||
        k.record.lines.size() != k.record.line_descriptors.size()) {
      return Status::Error("map keyframe " + std::to_string(k.record.id) + ": features and descriptors differ in count");
    }
  }
  for (const SavedLoopEdge& e : map.loop_edges) {
    if (!positiveDefinite(e.information)) return Status::Error("map loop edge: information is not positive definite");
  }
  for (const auto& kp : map.keyframes) {
    const SavedKeyframe& k = *kp;
    const int slot = free_slots_.back();
    free_slots_.pop_back();
    makeLoopCandidate(k.record, &records_[std::size_t(slot)]);
    Node& n = nodes_[std::size_t(slot)];
    n = Node{};
    n.id = k.record.id;
    n.timestamp_s = k.record.timestamp_s;
    n.T_world_cam = k.T_world_cam;
    n.T_world_record = k.record.T_world_cam;
    // The loading run's mapping frame is the map's graph frame (it relocalizes against these
    // keyframes at their optimised poses), not the first run's real-time frame its records were
    // made in: those differ by that run's corrections and final optimisation.
    n.T_world_mapping = k.T_world_cam;
    n.has_edge = k.has_edge;
    n.T_previous_this = k.T_previous_this;
    n.edge_covariance = k.edge_covariance;
    n.edge_length_m = k.edge_length_m;
    n.previous_map_id = k.previous_map_id;
    order_.push_back(slot);
    const LoopCandidate& r = records_[std::size_t(slot)];
    // Sized for capacity + 1 keyframes of at most kMaxLoopPoints + kMaxLoopLines words: cannot fail.
    (void)database_.insert(r.id, PlaceDescriptors{r.point_descriptors.data(), r.num_points,
                                                  r.line_descriptors.data(), r.num_lines});
  }
  loop_edges_.insert(loop_edges_.end(), map.loop_edges.begin(), map.loop_edges.end());
  stats_.graph_nodes = order_.size();
  stats_.peak_graph_nodes = std::max<uint64_t>(stats_.peak_graph_nodes, order_.size());
  stats_.loop_edges = loop_edges_.size();
  return Status::Ok();
}

}  // namespace plumb::loop

#include "pipeline/odometry/matcher.h"

#include <algorithm>
#include <cmath>

#include "pipeline/odometry/line_direction_bins.h"

namespace plumb {
namespace {

// Indices of the (up to) three fullest histogram bins; ORB-SLAM keeps the second and third only
// when they hold at least a tenth of the first.
void threeLargestBins(const int* counts, int bins, int* b1, int* b2, int* b3) {
  int m1 = 0, m2 = 0, m3 = 0;
  *b1 = *b2 = *b3 = -1;
  for (int i = 0; i < bins; ++i) {
    const int c = counts[i];
    if (c > m1) {
      m3 = m2; *b3 = *b2;
      m2 = m1; *b2 = *b1;
      m1 = c; *b1 = i;
    } else if (c > m2) {
      m3 = m2; *b3 = *b2;
      m2 = c; *b2 = i;
    } else if (c > m3) {
      m3 = c; *b3 = i;
    }
  }
  if (m2 < 0.1 * m1) { *b2 = -1; *b3 = -1; }
  else if (m3 < 0.1 * m1) { *b3 = -1; }
}

// Closest point on the 3D line (point, dir) to the camera ray through undistorted pixel (u, v).
bool pointOnLineNearRay(const PinholeCamera& camera, const Eigen::Vector3f& point, const Eigen::Vector3f& dir,
                        const Eigen::Vector2f& px, Eigen::Vector3d* out) {
  const Eigen::Vector3d ray((px.x() - camera.cx) / camera.fx, (px.y() - camera.cy) / camera.fy, 1.0);
  const Eigen::Vector3d a = point.cast<double>(), d = dir.cast<double>();
  // Minimise |a + t d - s ray|^2 over (t, s).
  const double dd = d.dot(d), dr = d.dot(ray), rr = ray.dot(ray);
  const double denom = dd * rr - dr * dr;
  if (std::abs(denom) < 1e-12) return false;  // ray parallel to the line
  const double ad = a.dot(d), ar = a.dot(ray);
  const double t = (dr * ar - rr * ad) / denom;
  *out = a + t * d;
  return out->z() > 0;
}

}  // namespace

ProjectionMatcher::ProjectionMatcher(const MatcherOptions& options) : options_(options) {
  for (int octave = 0; octave < kPyramidLevels; ++octave) {
    octave_scale_[octave] = std::pow(options_.scale_factor, static_cast<float>(octave));
  }
}

int ProjectionMatcher::matchPoints(const PointCandidate* candidates, int count, const FrameFeatures& frame,
                                   PointMatches& out) {
  out.clear();
  const PointMatcherOptions& o = options_.points;
  const int num_keypoints = static_cast<int>(frame.keypoints.size());
  if (!frame.keypoint_grid.built || num_keypoints == 0) return 0;
  std::fill_n(best_candidate_for_keypoint_.begin(), num_keypoints, -1);
  std::fill_n(best_distance_for_keypoint_.begin(), num_keypoints, 1 << 20);

  // The keypoints' octaves in grid order, so the octave test, which rejects most keypoints of a
  // window, reads them in sequence rather than through each keypoint's record.
  const KeypointGrid& grid = frame.keypoint_grid;
  const int slots = std::min<int>(grid.cell_start[KeypointGrid::kCols * KeypointGrid::kRows], kMaxKeypoints);
  for (int s = 0; s < slots; ++s) grid_octave_[s] = frame.keypoints.data()[grid.indices[s]].octave;
  // |octave - cand.octave| <= tolerance as one unsigned compare: octave - (cand.octave - t) in
  // [0, 2t] (octaves are int8, so a tolerance above 255 admits all, a negative one none).
  const int tolerance = std::min(o.octave_tolerance, 255);
  count = tolerance < 0 ? 0 : std::min(count, 65535);  // a negative tolerance admits no keypoint
  for (int c = 0; c < count; ++c) {
    const PointCandidate& cand = candidates[c];
    const float radius = o.search_radius_px * octaveScale(cand.octave);
    const float radius2 = radius * radius;
    const int lowest_octave = cand.octave - tolerance;
    const unsigned octave_span = static_cast<unsigned>(2 * tolerance);
    int best = 1 << 20, second = 1 << 20, best_kp = -1, best_octave = -1, second_octave = -1;
    grid.forEachSlotNear(cand.px_undist.x(), cand.px_undist.y(), radius, [&](int slot) {
      if (static_cast<unsigned>(grid_octave_[slot] - lowest_octave) > octave_span) return;
      const int k = grid.indices[slot];
      const KeypointObservation& kp = frame.keypoints[k];
      if ((kp.px_undist - cand.px_undist).squaredNorm() > radius2) return;
      const int d = hammingDistance(cand.descriptor, frame.keypoint_descriptors[k]);
      if (d < best) {
        second = best; second_octave = best_octave;
        best = d; best_kp = k; best_octave = kp.octave;
      } else if (d < second) {
        second = d; second_octave = kp.octave;
      }
    });
    if (best_kp < 0 || best > o.hamming_threshold) continue;
    // Ratio test against a rival on the same level (the same corner re-detected on a neighbouring
    // level is not a rival).
    if (second_octave == best_octave && best > o.ratio * second) continue;
    if (best < best_distance_for_keypoint_[best_kp]) {
      best_distance_for_keypoint_[best_kp] = best;
      best_candidate_for_keypoint_[best_kp] = c;
    }
  }

  // Orientation consistency: the rotation between prediction and observation is the same for
  // every correct match (up to noise), so matches outside the dominant bins are dropped.
  int bins_to_keep[3] = {-1, -1, -1};
  const int bins = std::max(1, o.orientation_bins);
  std::array<int, 360> histogram{};
  auto binOf = [bins](float observed, float predicted) {
    float rot = observed - predicted;
    if (rot < 0) rot += 360.f;
    int b = static_cast<int>(rot * bins / 360.f);
    return b >= bins ? bins - 1 : b;
  };
  const bool check = o.check_orientation && bins <= 360;
  if (check) {
    for (int k = 0; k < num_keypoints; ++k) {
      const int c = best_candidate_for_keypoint_[k];
      if (c >= 0 && candidates[c].angle_deg >= 0) ++histogram[binOf(frame.keypoints[k].angle_deg, candidates[c].angle_deg)];
    }
    threeLargestBins(histogram.data(), bins, &bins_to_keep[0], &bins_to_keep[1], &bins_to_keep[2]);
  }
  for (int k = 0; k < num_keypoints; ++k) {
    const int c = best_candidate_for_keypoint_[k];
    if (c < 0) continue;
    if (check && candidates[c].angle_deg >= 0) {
      const int b = binOf(frame.keypoints[k].angle_deg, candidates[c].angle_deg);
      if (b != bins_to_keep[0] && b != bins_to_keep[1] && b != bins_to_keep[2]) continue;
    }
    PointMatch m;
    m.candidate = static_cast<uint16_t>(c);
    m.keypoint = static_cast<uint16_t>(k);
    m.distance = static_cast<uint16_t>(best_distance_for_keypoint_[k]);
    if (!out.push_back(m)) break;
  }
  return static_cast<int>(out.size());
}

int ProjectionMatcher::matchLines(const LineCandidate* candidates, int count, const FrameFeatures& frame,
                                  LineMatches& out) const {
  out.clear();
  const LineMatcherOptions& o = options_.lines;
  const int num_lines = static_cast<int>(frame.lines.size());
  std::array<int, kMaxLines> best_candidate{}, best_distance{};
  best_candidate.fill(-1);
  best_distance.fill(1 << 20);
  const float cos_max_angle = std::cos(o.max_angle_deg * static_cast<float>(M_PI) / 180.f);
  count = std::min(count, 65535);
  // Per observed line, once instead of once per candidate (the same float operations, so the
  // same values): its span, its length, and the angle test's bound.
  std::array<Eigen::Vector2f, kMaxLines> obs_spans;
  obs_spans.fill(Eigen::Vector2f::Zero());  // read only below num_lines; GCC cannot tell
  std::array<float, kMaxLines> obs_lengths{}, angle_bounds;
  for (int k = 0; k < num_lines; ++k) {
    const LineObservation& obs = frame.lines[k];
    obs_spans[k] = obs.end_px - obs.start_px;
    obs_lengths[k] = obs_spans[k].norm();
    angle_bounds[k] = cos_max_angle * obs_lengths[k];
  }
  // Only the lines whose direction can pass the angle test are visited (line_direction_bins.h:
  // a superset of them, in index order, so the matches are those of testing every line).
  LineDirectionBins bins;  // 1.5 kB on the stack, like the arrays above
  bins.build(obs_spans.data(), obs_lengths.data(), num_lines, 1e-3f, o.max_angle_deg);
  for (int c = 0; c < count; ++c) {
    const LineCandidate& cand = candidates[c];
    const Eigen::Vector2f span = cand.end_px - cand.start_px;
    const float length = span.norm();
    if (length < 1e-3f) continue;
    const Eigen::Vector2f u = span / length;
    const Eigen::Vector2f n(-u.y(), u.x());
    int best = 1 << 20, second = 1 << 20, best_line = -1;
    forEachLine(bins.near(span), [&](int k) {
      const float obs_length = obs_lengths[k];
      if (obs_length < 1e-3f) return;
      if (std::abs(u.dot(obs_spans[k])) < angle_bounds[k]) return;  // undirected angle
      const LineObservation& obs = frame.lines[k];
      const Eigen::Vector2f ds = obs.start_px - cand.start_px, de = obs.end_px - cand.start_px;
      if (std::abs(n.dot(ds)) > o.max_endpoint_distance_px || std::abs(n.dot(de)) > o.max_endpoint_distance_px) return;
      const float t0 = std::min(u.dot(ds), u.dot(de)), t1 = std::max(u.dot(ds), u.dot(de));
      const float overlap = std::min(t1, length) - std::max(t0, 0.f);
      if (overlap < o.min_overlap * std::min(length, obs_length)) return;
      const int d = hammingDistance(cand.descriptor, frame.line_descriptors[k]);
      if (d < best) {
        second = best;
        best = d;
        best_line = k;
      } else if (d < second) {
        second = d;
      }
    });
    if (best_line < 0 || best > o.lbd_threshold || best > o.ratio * second) continue;
    if (best < best_distance[best_line]) {
      best_distance[best_line] = best;
      best_candidate[best_line] = c;
    }
  }
  for (int k = 0; k < num_lines; ++k) {
    if (best_candidate[k] < 0) continue;
    LineMatch m;
    m.candidate = static_cast<uint16_t>(best_candidate[k]);
    m.line = static_cast<uint16_t>(k);
    m.distance = static_cast<uint16_t>(best_distance[k]);
    if (!out.push_back(m)) break;
  }
  return static_cast<int>(out.size());
}

int ProjectionMatcher::matchPointsFrameToFrame(const PinholeCamera& camera, const FrameFeatures& previous,
                                               const Eigen::Isometry3d& T_current_previous,
                                               const FrameFeatures& current, PointMatches& out) {
  point_candidates_.clear();
  point_candidate_source_.clear();
  const float log_scale = std::log(options_.scale_factor);
  for (size_t i = 0; i < previous.keypoints.size(); ++i) {
    const KeypointObservation& kp = previous.keypoints[i];
    if (kp.depth_m <= 0) continue;
    const Eigen::Vector3d P_current = T_current_previous * kp.P_cam.cast<double>();
    if (P_current.z() <= 0) continue;
    const Eigen::Vector2d uv = camera.project(P_current);
    if (!camera.inImage(uv.x(), uv.y(), -20)) continue;
    PointCandidate* cand = point_candidates_.emplace_back();
    // Nearer than before -> the corner looks bigger -> found on a coarser level.
    const int octave = static_cast<int>(std::lround(kp.octave + std::log(kp.depth_m / P_current.z()) / log_scale));
    cand->px_undist = uv.cast<float>();
    cand->descriptor = previous.keypoint_descriptors[i];
    cand->octave = static_cast<int8_t>(std::clamp(octave, 0, kPyramidLevels - 1));
    cand->angle_deg = kp.angle_deg;
    (void)point_candidate_source_.push_back(static_cast<uint16_t>(i));
  }
  matchPoints(point_candidates_.data(), static_cast<int>(point_candidates_.size()), current, out);
  for (PointMatch& m : out) m.candidate = point_candidate_source_[m.candidate];
  return static_cast<int>(out.size());
}

int ProjectionMatcher::matchLinesFrameToFrame(const PinholeCamera& camera, const FrameFeatures& previous,
                                              const Eigen::Isometry3d& T_current_previous,
                                              const FrameFeatures& current, LineMatches& out) {
  line_candidates_.clear();
  line_candidate_source_.clear();
  for (size_t i = 0; i < previous.lines.size(); ++i) {
    const LineObservation& line = previous.lines[i];
    if (!line.has_3d) continue;
    Eigen::Vector3d S, E;
    if (!pointOnLineNearRay(camera, line.line_point_cam, line.line_dir_cam, line.start_px, &S) ||
        !pointOnLineNearRay(camera, line.line_point_cam, line.line_dir_cam, line.end_px, &E)) {
      continue;
    }
    const Eigen::Vector3d S_current = T_current_previous * S, E_current = T_current_previous * E;
    if (S_current.z() <= 0 || E_current.z() <= 0) continue;
    LineCandidate* cand = line_candidates_.emplace_back();
    cand->start_px = camera.project(S_current).cast<float>();
    cand->end_px = camera.project(E_current).cast<float>();
    cand->descriptor = previous.line_descriptors[i];
    (void)line_candidate_source_.push_back(static_cast<uint16_t>(i));
  }
  matchLines(line_candidates_.data(), static_cast<int>(line_candidates_.size()), current, out);
  for (LineMatch& m : out) m.candidate = line_candidate_source_[m.candidate];
  return static_cast<int>(out.size());
}

}  // namespace plumb

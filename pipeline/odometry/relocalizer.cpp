#include "pipeline/odometry/relocalizer.h"

#include <algorithm>
#include <random>
#include <type_traits>

#include <Eigen/Geometry>

#include "pipeline/frontend/descriptor_match.h"
#include "solver/noise_model.h"
#include "solver/pose_optimizer.h"
#include "solver/rigid_fit.h"
#include "solver/zero_page_allocator.h"

namespace plumb {

struct Relocalizer::Scratch {
  FixedVector<std::pair<float, uint16_t>, kMaxKeypoints> order;
  FixedVector<std::pair<int, int>, kMaxRelocKeyframes> ranked;  // (-score, ring index)
  FixedVector<uint16_t, kMaxKeypoints> prefilter;
  FixedVector<Correspondence, kMaxKeypoints> correspondences;
  std::array<bool, kMaxKeypoints> inlier{};
  std::array<bool, kMaxKeypoints> best_inlier{};
  std::array<Eigen::Vector3d, kMaxKeypoints> P_current, P_stored;  // the correspondences, for rigidRansac
  FixedVector<PosePointObservation, kMaxKeypoints> pose_points;
  std::array<bool, kMaxKeypoints> pose_inlier{};
};

Relocalizer::Relocalizer(const PinholeCamera& camera, const OdometryOptions& options)
    : camera_(camera),
      options_(options),
      stored_(kMaxRelocKeyframes),
      s_(ZeroPageAllocator<Scratch>().allocate(1)) {
  residency_.add(stored_.data(), stored_.size() * sizeof(StoredKeyframe));
  intrinsics_ = CameraIntrinsics{camera.fx, camera.fy, camera.cx, camera.cy, camera.fx * camera.baseline_m};
}

Relocalizer::~Relocalizer() = default;

void Relocalizer::ScratchDeleter::operator()(Scratch* s) const {
  static_assert(std::is_trivially_destructible_v<Scratch>, "released without a destructor call");
  ZeroPageAllocator<Scratch>().deallocate(s, 1);
}

Relocalizer::StoredKeyframe& Relocalizer::claimSlot(uint32_t keyframe_id, const Eigen::Isometry3d& T_world_cam) {
  // A slice of the ring made resident per keyframe from the second on (header): all of it after
  // ~5 keyframes, ~0.1 ms each where fresh memory costs ~0.4 ms/MiB.
  constexpr std::size_t kResidentBytesPerKeyframe = std::size_t(256) << 10;
  if (keyframes_added_++ > 0) residency_.step(kResidentBytesPerKeyframe);
  StoredKeyframe& kf = stored_[next_];
  next_ = (next_ + 1) % kMaxRelocKeyframes;
  count_ = std::min(count_ + 1, kMaxRelocKeyframes);
  kf.id = keyframe_id;
  kf.T_world_cam = T_world_cam;
  kf.descriptors.clear();
  kf.P_cam.clear();
  return kf;
}

void Relocalizer::addKeyframe(uint32_t keyframe_id, const Eigen::Isometry3d& T_world_cam,
                              const FrameFeatures& frame) {
  StoredKeyframe& kf = claimSlot(keyframe_id, T_world_cam);
  // The strongest keypoints with depth (index breaks response ties: deterministic).
  auto& order = s_->order;
  order.clear();
  for (std::size_t k = 0; k < frame.keypoints.size(); ++k) {
    if (frame.keypoints[k].depth_m > 0) (void)order.push_back({-frame.keypoints[k].response, uint16_t(k)});
  }
  const std::size_t keep = std::min(order.size(), kMaxRelocFeatures);
  std::partial_sort(order.begin(), order.begin() + keep, order.end());
  for (std::size_t i = 0; i < keep; ++i) {
    (void)kf.descriptors.push_back(frame.keypoint_descriptors[order[i].second]);
    (void)kf.P_cam.push_back(frame.keypoints[order[i].second].P_cam);
  }
}

void Relocalizer::addStoredKeyframe(uint32_t keyframe_id, const Eigen::Isometry3d& T_world_cam, std::size_t n,
                                    const Descriptor256* descriptors, const Eigen::Vector3f* P_cam) {
  StoredKeyframe& kf = claimSlot(keyframe_id, T_world_cam);
  for (std::size_t i = 0; i < std::min(n, kMaxRelocFeatures); ++i) {
    (void)kf.descriptors.push_back(descriptors[i]);
    (void)kf.P_cam.push_back(P_cam[i]);
  }
}

void Relocalizer::updatePose(uint32_t keyframe_id, const Eigen::Isometry3d& T_world_cam) {
  for (std::size_t i = 0; i < count_; ++i) {
    if (stored_[i].id == keyframe_id) stored_[i].T_world_cam = T_world_cam;
  }
}

int Relocalizer::countMatches(const StoredKeyframe& kf, const FrameFeatures& frame) const {
  int matches = 0;
  for (uint16_t k : s_->prefilter) {
    const Descriptor256& d = frame.keypoint_descriptors[k];
    int best = 256;
    for (const Descriptor256& other : kf.descriptors) best = std::min(best, hammingDistance(d, other));
    matches += best <= options_.relocalizer.hamming_threshold;
  }
  return matches;
}

int Relocalizer::matchAll(const StoredKeyframe& kf, const FrameFeatures& frame) {
  auto& out = s_->correspondences;
  out.clear();
  const RelocalizerOptions& o = options_.relocalizer;
  for (std::size_t k = 0; k < frame.keypoints.size(); ++k) {
    if (frame.keypoints[k].depth_m <= 0) continue;
    const Descriptor256& d = frame.keypoint_descriptors[k];
    const int best_index =
        bestRatioMatch(d, kf.descriptors.data(), kf.descriptors.size(), o.hamming_threshold, o.ratio);
    if (best_index < 0) continue;
    (void)out.push_back(Correspondence{uint16_t(k), frame.keypoints[k].P_cam.cast<double>(),
                                       kf.P_cam[std::size_t(best_index)].cast<double>()});
  }
  return int(out.size());
}

// RANSAC over minimal 3-point rigid fits, refitted on the inliers (solver/rigid_fit.h, shared with
// loop verification). The inlier threshold grows with depth squared like the sensor noise
// (inlier_threshold_m at 1 m).
bool Relocalizer::ransac(Eigen::Isometry3d* T_stored_current, int* inliers) {
  const auto& c = s_->correspondences;
  const int n = int(c.size());
  for (int i = 0; i < n; ++i) {
    s_->P_current[std::size_t(i)] = c[i].P_current;
    s_->P_stored[std::size_t(i)] = c[i].P_stored;
  }
  const RelocalizerOptions& o = options_.relocalizer;
  RigidRansacOptions ransac;
  ransac.iterations = o.ransac_iterations;
  ransac.inlier_threshold_m = o.inlier_threshold_m;
  ransac.seed = uint32_t(o.seed);
  *inliers = rigidRansac(s_->P_current.data(), s_->P_stored.data(), n, ransac, s_->inlier.data(),
                         s_->best_inlier.data(), T_stored_current);
  return *inliers >= 3;
}

int Relocalizer::refine(const FrameFeatures& frame, const StoredKeyframe& kf, Eigen::Isometry3d* T_cam_world) {
  const auto& c = s_->correspondences;
  auto& points = s_->pose_points;
  points.clear();
  const NoiseModelOptions& noise = options_.extractor.noise;
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (!s_->best_inlier[i]) continue;
    const KeypointObservation& kp = frame.keypoints[c[i].keypoint];
    PosePointObservation* obs = points.emplace_back();
    obs->P_world = kf.T_world_cam * c[i].P_stored;
    obs->has_depth = kp.depth_m > 0;
    obs->z = Eigen::Vector3d(kp.px_undist.x(), kp.px_undist.y(), obs->has_depth ? kp.u_right : 0.0);
    obs->information = kp.info_uvr.cast<double>();
    if (!obs->has_depth || !(obs->information.trace() > 0)) {
      obs->information.setZero();
      obs->information.topLeftCorner<2, 2>() = monoPointInformation(noise, kp.octave);
      obs->has_depth = false;
    }
  }
  PoseOptimizerOptions pose_options;
  const PoseResult pose = optimizePose(intrinsics_, *T_cam_world, points.data(), int(points.size()), nullptr, 0,
                                       pose_options, s_->pose_inlier.data(), nullptr);
  *T_cam_world = pose.T_cam_world;
  return pose.num_point_inliers;
}

RelocResult Relocalizer::relocalize(const FrameFeatures& frame, Eigen::Isometry3d* T_world_cam) {
  RelocResult result;
  const RelocalizerOptions& o = options_.relocalizer;
  // A deterministic subset spread over the keypoint list for ranking.
  s_->prefilter.clear();
  int with_depth = 0;
  for (const auto& kp : frame.keypoints) with_depth += kp.depth_m > 0;
  if (with_depth < o.min_inliers) return result;
  const int step = std::max(1, with_depth / std::max(1, o.prefilter_features));
  int seen = 0;
  for (std::size_t k = 0; k < frame.keypoints.size(); ++k) {
    if (frame.keypoints[k].depth_m <= 0) continue;
    if (seen++ % step == 0) (void)s_->prefilter.push_back(uint16_t(k));
  }

  s_->ranked.clear();
  for (std::size_t i = 0; i < count_; ++i) {
    const int score = countMatches(stored_[i], frame);
    // Scaled to the full feature count for the min_matches comparison.
    if (score * step >= o.min_matches) (void)s_->ranked.push_back({-score, int(i)});
  }
  std::sort(s_->ranked.begin(), s_->ranked.end());
  for (std::size_t r = 0; r < s_->ranked.size() && int(r) < o.candidates; ++r) {
    const StoredKeyframe& kf = stored_[std::size_t(s_->ranked[r].second)];
    ++result.candidates_tried;
    const int matches = matchAll(kf, frame);
    if (matches < o.min_matches) continue;
    Eigen::Isometry3d T_stored_current;
    int inliers = 0;
    if (!ransac(&T_stored_current, &inliers) || inliers < o.min_inliers) continue;
    Eigen::Isometry3d T_cam_world = (kf.T_world_cam * T_stored_current).inverse();
    const int refined = refine(frame, kf, &T_cam_world);
    result.matches = matches;
    result.ransac_inliers = inliers;
    result.refined_inliers = refined;
    if (refined < o.min_inliers) continue;
    result.success = true;
    result.keyframe_id = kf.id;
    *T_world_cam = T_cam_world.inverse();
    return result;
  }
  return result;
}

}  // namespace plumb

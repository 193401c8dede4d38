// LocalMapper (pipeline/odometry/local_mapper.h) fed hand-built KeyframeRequests: landmarks made
// from depth, snapshots that grow in version, culling of unconfirmed / rarely found landmarks,
// the keyframe capacity with retirement, covariances, and local BA holding the first keyframe.
//
// Requests are made without the tracker: keypoints are associated with the snapshot's landmarks
// by their (unique, random) descriptors, which is the association the tracker should find.
#include <algorithm>
#include <memory>

#include <gtest/gtest.h>

#include "pipeline/odometry/local_mapper.h"
#include "tests/support/synthetic_features.h"

namespace plumb {
namespace {

using test::pose;
using test::translationError;

const Eigen::Isometry3d kStart = pose(-8, Eigen::Vector3d(1, 0.5, 0), Eigen::Vector3d(-0.2, 0.1, 0.4));

bool sameDescriptor(const Descriptor256& a, const Descriptor256& b) { return a.words == b.words; }

// A keyframe request for `view` taken at T_world_cam, associated with `snapshot` by descriptor.
// Only the first `max_associated` keypoints are associated (the rest become new landmarks).
std::unique_ptr<KeyframeRequest> trackedRequest(const test::View& view, const Eigen::Isometry3d& T_world_cam,
                                                uint64_t sequence, const LocalMap& snapshot,
                                                std::size_t max_associated = kMaxKeypoints) {
  auto r = test::newMapRequest(view, T_world_cam, sequence);
  r->start_new_map = false;
  r->local_map_version = snapshot.version;
  const FrameFeatures& f = *view.features;
  for (std::size_t k = 0; k < std::min(f.keypoints.size(), max_associated); ++k) {
    for (const LocalMapPoint& p : snapshot.points) {
      if (sameDescriptor(p.descriptor, f.keypoint_descriptors[k])) r->keypoint_landmark[k] = p.ref;
    }
  }
  for (std::size_t k = 0; k < f.lines.size(); ++k) {
    for (const LocalMapLine& l : snapshot.lines) {
      if (sameDescriptor(l.descriptor, f.line_descriptors[k])) r->line_landmark[k] = l.ref;
    }
  }
  return r;
}

int associatedPoints(const KeyframeRequest& r) {
  int n = 0;
  for (std::size_t k = 0; k < r.features.keypoints.size(); ++k) n += r.keypoint_landmark[k].id != 0;
  return n;
}

struct Fixture {
  PinholeCamera camera = test::syntheticCamera();
  OdometryOptions options;
  std::unique_ptr<LocalMapper> mapper;
  explicit Fixture(const OdometryOptions& o = OdometryOptions()) : options(o) {
    mapper = std::make_unique<LocalMapper>(camera, options);
  }
};

TEST(LocalMapper, NewMapCreatesLandmarksFromDepthAndPublishesASnapshot) {
  // Depths 1-8 m (the mapper keeps <= 6 m), every 4th point without depth.
  const test::Scene scene = test::makeScene(11, 300, 25, kStart, 1.0, 8.0);
  const test::View view = test::observe(scene, kStart, 4);
  int expected_points = 0;
  for (const KeypointObservation& kp : view.features->keypoints) expected_points += kp.depth_m > 0 && kp.depth_m <= 6.0;
  ASSERT_GT(expected_points, 100);
  ASSERT_LT(expected_points, int(view.features->keypoints.size()));  // both exclusions occur

  Fixture fx;
  EXPECT_EQ(fx.mapper->localMap().version, 0u);
  const auto request = test::newMapRequest(view, kStart, 7);
  const InsertResult r = fx.mapper->insertKeyframe(*request);
  ASSERT_TRUE(r.inserted);
  EXPECT_EQ(r.new_points, expected_points);
  EXPECT_EQ(r.new_lines, int(view.features->lines.size()));
  EXPECT_EQ(fx.mapper->map().counts().keyframes, 1u);
  EXPECT_EQ(fx.mapper->map().counts().points, std::size_t(expected_points));

  const LocalMap& map = fx.mapper->localMap();
  EXPECT_EQ(map.version, 1u);
  EXPECT_EQ(map.segment, 1u);
  EXPECT_EQ(map.reference_keyframe_id, r.keyframe_id);
  EXPECT_EQ(map.reference_keyframe_sequence, 7u);
  EXPECT_TRUE(map.T_world_reference.isApprox(kStart, 1e-12));
  ASSERT_EQ(map.keyframes.size(), 1u);
  EXPECT_EQ(map.keyframes[0].id, r.keyframe_id);
  ASSERT_EQ(map.points.size(), std::size_t(expected_points));
  ASSERT_EQ(map.lines.size(), view.features->lines.size());
  // Each landmark sits where its scene point is (found by its descriptor), within 6 m.
  for (const LocalMapPoint& p : map.points) {
    const test::ScenePoint* truth = nullptr;
    for (const test::ScenePoint& s : scene.points) {
      if (sameDescriptor(s.descriptor, p.descriptor)) truth = &s;
    }
    ASSERT_NE(truth, nullptr);
    EXPECT_LT((p.P_world - truth->P_world).norm(), 1e-5);
    EXPECT_LE((kStart.inverse() * p.P_world).z(), 6.0 + 1e-6);
  }
  for (const LocalMapLine& l : map.lines) {
    const test::SceneLine* truth = nullptr;
    for (const test::SceneLine& s : scene.lines) {
      if (sameDescriptor(s.descriptor, l.descriptor)) truth = &s;
    }
    ASSERT_NE(truth, nullptr);
    // Samples and the segment's endpoints lie on the scene segment.
    const Eigen::Vector3d dir = (truth->B_world - truth->A_world).normalized();
    auto off_line = [&](const Eigen::Vector3d& X) {
      const Eigen::Vector3d d = X - truth->A_world;
      return (d - d.dot(dir) * dir).norm();
    };
    ASSERT_EQ(l.num_samples, 5);
    for (int s = 0; s < l.num_samples; ++s) EXPECT_LT(off_line(l.samples_world[s]), 1e-5);
    EXPECT_LT((l.start_world - truth->A_world).norm(), 1e-4);
    EXPECT_LT((l.end_world - truth->B_world).norm(), 1e-4);
  }
}

TEST(LocalMapper, NewPointsPerKeyframeAreCappedClosestFirst) {
  const test::Scene scene = test::makeScene(12, 500, 0, kStart, 1.0, 5.0);
  const test::View view = test::observe(scene, kStart);
  OdometryOptions options;
  options.mapper.max_new_points = 120;
  Fixture fx(options);
  const InsertResult r = fx.mapper->insertKeyframe(*test::newMapRequest(view, kStart, 0));
  ASSERT_EQ(r.new_points, 120);
  // The 120 closest: every landmark is nearer than every keypoint left out.
  std::vector<float> depths;
  for (const KeypointObservation& kp : view.features->keypoints) depths.push_back(kp.depth_m);
  std::sort(depths.begin(), depths.end());
  const double cut = 0.5 * (double(depths[119]) + double(depths[120]));
  for (const LocalMapPoint& p : fx.mapper->localMap().points) EXPECT_LT((kStart.inverse() * p.P_world).z(), cut);
}

TEST(LocalMapper, KeyframeWithoutAMapIsRefused) {
  const test::Scene scene = test::makeScene(13, 100, 0, kStart);
  const test::View view = test::observe(scene, kStart);
  Fixture fx;
  LocalMap empty;
  const InsertResult r = fx.mapper->insertKeyframe(*trackedRequest(view, kStart, 0, empty));
  EXPECT_FALSE(r.inserted);
  EXPECT_EQ(fx.mapper->localMap().version, 0u);
  EXPECT_EQ(fx.mapper->map().counts().keyframes, 0u);
}

TEST(LocalMapper, TrackedKeyframesReuseLandmarksAndVersionsIncrease) {
  const test::Scene scene = test::makeScene(14, 300, 20, kStart, 1.5, 5.0);
  Fixture fx;
  Eigen::Isometry3d T = kStart;
  const test::View v0 = test::observe(scene, T);
  const InsertResult first = fx.mapper->insertKeyframe(*test::newMapRequest(v0, T, 0));
  const std::size_t landmarks = fx.mapper->map().counts().points;
  uint64_t version = fx.mapper->localMap().version;
  const Eigen::Isometry3d step = pose(0.5, Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0.01, 0, 0.005));
  for (int i = 1; i <= 3; ++i) {
    T = T * step;
    const test::View v = test::observe(scene, T);
    const auto request = trackedRequest(v, T, uint64_t(i), fx.mapper->localMap());
    const int associated = associatedPoints(*request);
    ASSERT_GT(associated, 250);
    const InsertResult r = fx.mapper->insertKeyframe(*request);
    ASSERT_TRUE(r.inserted);
    EXPECT_GT(r.keyframe_id, first.keyframe_id);
    // Every keypoint with depth was associated (the scene is the one the map was made of).
    EXPECT_EQ(r.new_points, int(v.features->keypoints.size()) - associated);
    EXPECT_EQ(r.ba_outliers, 0);
    const LocalMap& map = fx.mapper->localMap();
    EXPECT_GT(map.version, version);
    version = map.version;
    EXPECT_EQ(map.keyframes_in_map, i + 1);
    EXPECT_EQ(map.reference_keyframe_id, r.keyframe_id);
    EXPECT_EQ(map.reference_keyframe_sequence, uint64_t(i));
  }
  EXPECT_EQ(fx.mapper->map().counts().points, landmarks);
  // With more than two keyframes the reference's tracked landmarks are those with >= 2 observers:
  // all of them here.
  const LocalMap& map = fx.mapper->localMap();
  EXPECT_GT(map.reference_tracked_landmarks, 250);
  EXPECT_GE(fx.mapper->stats().ba_runs, 3u);
}

TEST(LocalMapper, LocalBaHoldsTheFirstKeyframeAndPullsAPerturbedOneToTheTruth) {
  const test::Scene scene = test::makeScene(15, 300, 0, kStart, 1.0, 4.0);
  Fixture fx;
  fx.mapper->insertKeyframe(*test::newMapRequest(test::observe(scene, kStart), kStart, 0));
  const uint32_t first_id = fx.mapper->localMap().reference_keyframe_id;

  const Eigen::Isometry3d T_true = kStart * pose(2, Eigen::Vector3d(0, 1, 0.3), Eigen::Vector3d(0.05, 0.01, 0.02));
  // The tracker's pose is 1 cm / 0.3 deg off; the observations are exact at the true pose.
  const Eigen::Isometry3d T_tracked = pose(0.3, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0.006, -0.006, 0.005)) * T_true;
  const test::View view = test::observe(scene, T_true);
  // 200 keypoints tie the keyframe to the map; the rest become new landmarks, placed from the
  // tracker's (wrong) pose until BA moves them with the keyframe.
  const auto request = trackedRequest(view, T_tracked, 1, fx.mapper->localMap(), 200);
  ASSERT_EQ(associatedPoints(*request), 200);
  const InsertResult r = fx.mapper->insertKeyframe(*request);
  ASSERT_TRUE(r.inserted);
  const int fresh = int(view.features->keypoints.size()) - 200;
  ASSERT_GT(fresh, 50);
  EXPECT_EQ(r.new_points, fresh);
  EXPECT_LT(r.ba_final_cost, 0.01 * r.ba_initial_cost);
  int fresh_checked = 0;
  for (const LocalMapPoint& p : fx.mapper->localMap().points) {
    for (std::size_t k = 200; k < view.features->keypoints.size(); ++k) {
      if (!sameDescriptor(p.descriptor, view.features->keypoint_descriptors[k])) continue;
      ++fresh_checked;
      const Eigen::Vector3d truth = scene.points[std::size_t(view.keypoint_point[k])].P_world;
      EXPECT_LT((p.P_world - truth).norm(), 2e-3) << "new landmark of keypoint " << k;
    }
  }
  // Each of those scene points has two landmarks now: the first keyframe's (exact) and the new
  // one (as when a tracker misses a match); both must sit at the truth.
  EXPECT_EQ(fresh_checked, 2 * fresh);

  const LocalMap& map = fx.mapper->localMap();
  ASSERT_EQ(map.keyframes.size(), 2u);
  ASSERT_EQ(map.keyframes[0].id, first_id);
  // The first keyframe is the gauge: not moved at all.
  EXPECT_TRUE(map.keyframes[0].T_world_cam.isApprox(kStart, 1e-15));
  const double before = translationError(T_tracked, T_true);
  const double after = translationError(map.keyframes[1].T_world_cam, T_true);
  EXPECT_GT(before, 0.009);
  EXPECT_LT(after, 1e-3);
  EXPECT_LT(test::rotationErrorDeg(map.keyframes[1].T_world_cam, T_true), 0.03);
  EXPECT_TRUE(map.T_world_reference.isApprox(map.keyframes[1].T_world_cam, 1e-15));
}

// Split map updates: addKeyframe() hands out the keyframe at its tracked pose with its new
// landmarks before any BA, refineKeyframe() then publishes the BA's map (the scene of the test
// above: the tracked pose 1 cm off, which the BA corrects).
TEST(LocalMapper, AddKeyframeGivesTheFreshMapAndRefineKeyframeTheAdjustedOne) {
  const test::Scene scene = test::makeScene(15, 300, 0, kStart, 1.0, 4.0);
  Fixture fx;
  LocalMap fresh;
  InsertResult first = fx.mapper->addKeyframe(*test::newMapRequest(test::observe(scene, kStart), kStart, 0), &fresh);
  ASSERT_TRUE(first.inserted);
  EXPECT_EQ(fresh.reference_keyframe_id, first.keyframe_id);
  EXPECT_EQ(fx.mapper->localMap().version, 0u);  // not published before refineKeyframe()
  EXPECT_FALSE(fx.mapper->refineKeyframe(&first)) << "a new map has no BA";
  EXPECT_GT(fx.mapper->localMap().version, fresh.version);
  EXPECT_EQ(fx.mapper->localMap().points.size(), fresh.points.size());
  EXPECT_FALSE(fx.mapper->refineKeyframe(&first)) << "nothing left to refine";

  const Eigen::Isometry3d T_true = kStart * pose(2, Eigen::Vector3d(0, 1, 0.3), Eigen::Vector3d(0.05, 0.01, 0.02));
  const Eigen::Isometry3d T_tracked = pose(0.3, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0.006, -0.006, 0.005)) * T_true;
  const test::View view = test::observe(scene, T_true);
  const auto request = trackedRequest(view, T_tracked, 1, fx.mapper->localMap(), 200);
  const uint64_t published = fx.mapper->localMap().version;
  InsertResult r = fx.mapper->addKeyframe(*request, &fresh);
  ASSERT_TRUE(r.inserted);
  EXPECT_EQ(r.ba_initial_cost, 0.0);  // no BA yet
  EXPECT_EQ(fx.mapper->localMap().version, published);
  EXPECT_GT(fresh.version, published);
  EXPECT_EQ(fresh.reference_keyframe_id, r.keyframe_id);
  EXPECT_TRUE(fresh.T_world_reference.isApprox(T_tracked, 1e-15)) << "the tracked pose, unrefined";
  EXPECT_EQ(fresh.keyframes_in_map, 2);
  // The new keyframe's landmarks are in the fresh map, placed from the tracked pose.
  int new_landmarks = 0;
  for (const LocalMapPoint& p : fresh.points) {
    for (std::size_t k = 200; k < view.features->keypoints.size(); ++k) {
      if (!sameDescriptor(p.descriptor, view.features->keypoint_descriptors[k])) continue;
      const Eigen::Vector3d P_cam = view.features->keypoints[k].P_cam.cast<double>();
      new_landmarks += (p.P_world - T_tracked * P_cam).norm() < 1e-9;  // the other copy is the first keyframe's
    }
  }
  EXPECT_EQ(new_landmarks, r.new_points);

  EXPECT_TRUE(fx.mapper->refineKeyframe(&r));
  EXPECT_LT(r.ba_final_cost, 0.01 * r.ba_initial_cost);
  const LocalMap& refined = fx.mapper->localMap();
  EXPECT_GT(refined.version, fresh.version);
  EXPECT_EQ(refined.reference_keyframe_id, r.keyframe_id);
  EXPECT_LT(translationError(refined.T_world_reference, T_true), 1e-3);
  EXPECT_GT(translationError(fresh.T_world_reference, T_true), 0.009);
}

// Which scene points (by index) have a landmark in the snapshot.
std::vector<bool> scenePointsInMap(const test::Scene& scene, const LocalMap& map) {
  std::vector<bool> in_map(scene.points.size(), false);
  for (const LocalMapPoint& p : map.points) {
    for (std::size_t s = 0; s < scene.points.size(); ++s) {
      if (sameDescriptor(p.descriptor, scene.points[s].descriptor)) in_map[s] = true;
    }
  }
  return in_map;
}

TEST(LocalMapper, CullsUnconfirmedAndRarelyFoundLandmarks) {
  const test::Scene scene = test::makeScene(16, 200, 0, kStart, 1.0, 4.0);
  Fixture fx;
  fx.mapper->insertKeyframe(*test::newMapRequest(test::observe(scene, kStart), kStart, 0));
  ASSERT_EQ(fx.mapper->map().counts().points, 200u);

  // Later keyframes re-observe only scene points 20..149. With the second keyframe the tracker
  // reports points 0..19 as visible in 10 frames but never found.
  test::Scene seen;
  seen.points.assign(scene.points.begin() + 20, scene.points.begin() + 150);
  Eigen::Isometry3d T = kStart;
  auto next = [&](int i, bool report_unfound) {
    T = T * pose(0.4, Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0.01, 0.0, 0.0));
    const test::View v = test::observe(seen, T);
    ASSERT_EQ(v.features->keypoints.size(), 130u);
    const LocalMap& snapshot = fx.mapper->localMap();
    auto request = trackedRequest(v, T, uint64_t(i), snapshot);
    ASSERT_EQ(associatedPoints(*request), 130);
    if (report_unfound) {
      for (const LocalMapPoint& p : snapshot.points) {
        for (std::size_t s = 0; s < 20; ++s) {
          if (sameDescriptor(p.descriptor, scene.points[s].descriptor)) {
            (void)request->point_visibility.push_back(LandmarkVisibility{p.ref, 10, 0});
          }
        }
      }
      ASSERT_EQ(request->point_visibility.size(), 20u);
    }
    const InsertResult r = fx.mapper->insertKeyframe(*request);
    ASSERT_TRUE(r.inserted);
    EXPECT_EQ(r.new_points, 0);
  };

  // Keyframe 2: points 0..19 were found in 1 of 11 frames (creation counts as one): culled.
  // Points 150..199 are one keyframe old: kept for now.
  next(1, true);
  std::vector<bool> in_map = scenePointsInMap(scene, fx.mapper->localMap());
  for (std::size_t s = 0; s < 200; ++s) EXPECT_EQ(in_map[s], s >= 20) << "after keyframe 2, scene point " << s;
  EXPECT_EQ(fx.mapper->map().counts().points, 180u);

  // Keyframe 3: points 150..199 still have one observer two keyframes on: unconfirmed, culled.
  next(2, false);
  in_map = scenePointsInMap(scene, fx.mapper->localMap());
  for (std::size_t s = 0; s < 200; ++s) EXPECT_EQ(in_map[s], s >= 20 && s < 150) << "after keyframe 3, scene point " << s;
  EXPECT_EQ(fx.mapper->map().counts().points, 130u);
  EXPECT_EQ(fx.mapper->stats().points_culled, 70u);
}

// The snapshot's landmark of a scene point (by descriptor), or nullptr.
const LocalMapPoint* landmarkOf(const LocalMap& map, const test::ScenePoint& s) {
  for (const LocalMapPoint& p : map.points) {
    if (sameDescriptor(p.descriptor, s.descriptor)) return &p;
  }
  return nullptr;
}

// A third keyframe associates five keypoints with the wrong landmarks (gross outliers: each is a
// different scene point, metres away). Local BA flags them after solve() and the mapper removes
// exactly those observations, after the covariance (which must not reset the flags), while the
// landmarks keep their two correct observations.
// Five keypoints of a third keyframe associated with the wrong landmarks: the BA flags them; with
// `remove_ba_outliers` they leave the map, by default they are only counted.
class LocalMapperBaOutliers : public ::testing::TestWithParam<bool> {};

TEST_P(LocalMapperBaOutliers, AreFlaggedAndLeaveTheMapOnlyWhenEnabled) {
  const bool remove = GetParam();
  const test::Scene scene = test::makeScene(19, 200, 0, kStart, 1.0, 4.0);
  OdometryOptions options;
  options.mapper.remove_ba_outliers = remove;
  Fixture fx(options);
  fx.mapper->insertKeyframe(*test::newMapRequest(test::observe(scene, kStart), kStart, 0));
  const Eigen::Isometry3d step = pose(0.5, Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0.01, 0, 0.005));
  const Eigen::Isometry3d T1 = kStart * step;
  ASSERT_TRUE(fx.mapper->insertKeyframe(*trackedRequest(test::observe(scene, T1), T1, 1, fx.mapper->localMap())).inserted);
  constexpr int kWrong = 5;
  for (int s = 0; s < 2 * kWrong; ++s) {
    const LocalMapPoint* p = landmarkOf(fx.mapper->localMap(), scene.points[std::size_t(s)]);
    ASSERT_NE(p, nullptr) << s;
    ASSERT_EQ(p->keyframe_observations, 2) << s;
  }

  // The third keyframe sees scene points 5..199; its keypoints of points 5..9 are associated with
  // the landmarks of points 0..4 instead.
  test::Scene seen;
  seen.points.assign(scene.points.begin() + kWrong, scene.points.end());
  const Eigen::Isometry3d T2 = T1 * step;
  const test::View v = test::observe(seen, T2);
  auto request = trackedRequest(v, T2, 2, fx.mapper->localMap());
  int wrong = 0;
  for (std::size_t k = 0; k < v.features->keypoints.size(); ++k) {
    const int s = v.keypoint_point[k] + kWrong;  // scene index
    if (s >= 2 * kWrong) continue;
    const test::ScenePoint& other = scene.points[std::size_t(s - kWrong)];
    ASSERT_GT((other.P_world - scene.points[std::size_t(s)].P_world).norm(), 0.2);
    request->keypoint_landmark[k] = landmarkOf(fx.mapper->localMap(), other)->ref;
    ++wrong;
  }
  ASSERT_EQ(wrong, kWrong);
  const InsertResult r = fx.mapper->insertKeyframe(*request);
  ASSERT_TRUE(r.inserted);
  EXPECT_EQ(r.new_points, 0);
  EXPECT_GE(fx.mapper->stats().ba_outlier_flags, uint64_t(kWrong));
  if (!remove) {
    // Counted, not acted on: points 0..4 keep their wrong third observation.
    EXPECT_EQ(r.ba_outliers, 0);
    EXPECT_EQ(fx.mapper->stats().ba_outlier_observations, 0u);
    for (std::size_t s = 0; s < 2 * kWrong; ++s) {
      const LocalMapPoint* p = landmarkOf(fx.mapper->localMap(), scene.points[s]);
      ASSERT_NE(p, nullptr) << s;
      EXPECT_EQ(p->keyframe_observations, s < kWrong ? 3 : 2) << "scene point " << s;
    }
    return;
  }
  EXPECT_EQ(r.ba_outliers, kWrong);
  EXPECT_EQ(fx.mapper->stats().ba_outlier_observations, uint64_t(kWrong));
  // Points 0..9: their two correct observations (points 5..9 lost none: the keypoints were
  // associated elsewhere); every other point has all three. The culled observations still pulled
  // this BA's estimate of their landmarks (the kernel bounds it: ~1 cm here; the mapper solves
  // once, culling afterwards), not that of the others.
  const LocalMap& map = fx.mapper->localMap();
  for (std::size_t s = 0; s < scene.points.size(); ++s) {
    const LocalMapPoint* p = landmarkOf(map, scene.points[s]);
    ASSERT_NE(p, nullptr) << s;
    EXPECT_EQ(p->keyframe_observations, s < 2 * kWrong ? 2 : 3) << "scene point " << s;
    EXPECT_LT((p->P_world - scene.points[s].P_world).norm(), s < kWrong ? 3e-2 : 1e-3) << "scene point " << s;
  }
  EXPECT_LT(translationError(map.T_world_reference, T2), 1e-3);

  // The next keyframe's BA no longer sees them: every landmark is back at the truth (with the
  // wrong observations kept, the pull would stay).
  const Eigen::Isometry3d T3 = T2 * step;
  const InsertResult r3 = fx.mapper->insertKeyframe(*trackedRequest(test::observe(scene, T3), T3, 3, fx.mapper->localMap()));
  ASSERT_TRUE(r3.inserted);
  EXPECT_EQ(r3.ba_outliers, 0);
  for (std::size_t s = 0; s < scene.points.size(); ++s) {
    const LocalMapPoint* p = landmarkOf(fx.mapper->localMap(), scene.points[s]);
    ASSERT_NE(p, nullptr) << s;
    EXPECT_LT((p->P_world - scene.points[s].P_world).norm(), 1e-3) << "after the next keyframe, scene point " << s;
  }
}

INSTANTIATE_TEST_SUITE_P(LocalMapper, LocalMapperBaOutliers, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& info) { return info.param ? "Removed" : "CountedByDefault"; });

TEST(LocalMapper, KeyframeCapacityRetiresTheOldestWithCovariances) {
  const test::Scene scene = test::makeScene(17, 150, 0, kStart, 2.0, 5.0);
  Fixture fx;
  const int total = int(kMaxMapKeyframes) + 6;
  Eigen::Isometry3d T = kStart;
  fx.mapper->insertKeyframe(*test::newMapRequest(test::observe(scene, T), T, 0));
  std::vector<uint32_t> ids = {fx.mapper->localMap().reference_keyframe_id};
  for (int i = 1; i < total; ++i) {
    T = T * pose(0.2, Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0.004, 0.0, 0.002));
    const test::View v = test::observe(scene, T);
    const InsertResult r = fx.mapper->insertKeyframe(*trackedRequest(v, T, uint64_t(i), fx.mapper->localMap()));
    ASSERT_TRUE(r.inserted) << i;
    ids.push_back(r.keyframe_id);
    ASSERT_LE(fx.mapper->map().counts().keyframes, kMaxMapKeyframes);
  }
  EXPECT_EQ(fx.mapper->map().counts().keyframes, kMaxMapKeyframes);
  EXPECT_EQ(fx.mapper->localMap().keyframes_in_map, int(kMaxMapKeyframes));
  // The oldest six left, oldest first, while the newest stay.
  const auto& retired = fx.mapper->retired();
  ASSERT_EQ(retired.size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(retired[i].id, ids[i]);
    EXPECT_EQ(retired[i].frame_sequence, i);
    // The very first keyframe is the gauge of every BA: never optimised, no covariance.
    EXPECT_EQ(retired[i].covariance_valid, i > 0) << i;
  }
  EXPECT_EQ(fx.mapper->localMap().keyframes[0].id, ids[6]);
  EXPECT_EQ(fx.mapper->localMap().keyframes[kMaxMapKeyframes - 1].id, ids.back());

  fx.mapper->clearRetired();
  fx.mapper->retireAll();
  EXPECT_EQ(fx.mapper->map().counts().keyframes, 0u);
  EXPECT_EQ(fx.mapper->map().counts().points, 0u);  // no observer left
  EXPECT_EQ(fx.mapper->localMap().version, 0u);
  ASSERT_EQ(fx.mapper->retired().size(), kMaxMapKeyframes);
  for (std::size_t i = 0; i < kMaxMapKeyframes; ++i) {
    const RetiredKeyframe& kf = fx.mapper->retired()[i];
    EXPECT_EQ(kf.id, ids[6 + i]);
    // Every keyframe but the first was optimised by some BA window: it has a covariance.
    ASSERT_TRUE(kf.covariance_valid) << i;
    EXPECT_TRUE(kf.covariance.isApprox(kf.covariance.transpose(), 1e-9));
    EXPECT_GT(kf.covariance.ldlt().vectorD().minCoeff(), 0.0) << i;
  }
}

TEST(LocalMapper, NewMapRetiresTheOldSegment) {
  const test::Scene scene = test::makeScene(18, 150, 0, kStart);
  Fixture fx;
  fx.mapper->insertKeyframe(*test::newMapRequest(test::observe(scene, kStart), kStart, 0));
  const Eigen::Isometry3d T1 = kStart * pose(0.5, Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0.01, 0, 0));
  fx.mapper->insertKeyframe(*trackedRequest(test::observe(scene, T1), T1, 1, fx.mapper->localMap()));
  const uint64_t version = fx.mapper->localMap().version;
  fx.mapper->clearRetired();

  const InsertResult r = fx.mapper->insertKeyframe(*test::newMapRequest(test::observe(scene, kStart), kStart, 2));
  ASSERT_TRUE(r.inserted);
  EXPECT_EQ(fx.mapper->segment(), 2u);
  EXPECT_EQ(fx.mapper->localMap().segment, 2u);
  EXPECT_GT(fx.mapper->localMap().version, version);
  EXPECT_EQ(fx.mapper->localMap().keyframes_in_map, 1);
  ASSERT_EQ(fx.mapper->retired().size(), 2u);
  EXPECT_EQ(fx.mapper->retired()[0].frame_sequence, 0u);
  EXPECT_EQ(fx.mapper->retired()[1].frame_sequence, 1u);
  EXPECT_EQ(fx.mapper->map().counts().points, 150u);
}

}  // namespace
}  // namespace plumb

namespace plumb {
namespace {

// Loop closing's correction (docs/LOOP.md "Correction"): one rigid motion of the whole local map,
// a new snapshot, and a request tracked against the old snapshot lands in the corrected frame.
TEST(LocalMapper, LoopCorrectionMovesTheWholeMapRigidlyAndLateRequestsFollow) {
  const test::Scene scene = test::makeScene(15, 300, 20, kStart, 1.5, 5.0);
  Fixture fx;
  Eigen::Isometry3d T = kStart;
  fx.mapper->insertKeyframe(*test::newMapRequest(test::observe(scene, T), T, 0));
  const Eigen::Isometry3d step = pose(0.5, Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0.01, 0, 0.005));
  for (int i = 1; i <= 2; ++i) {
    T = T * step;
    ASSERT_TRUE(fx.mapper->insertKeyframe(*trackedRequest(test::observe(scene, T), T, uint64_t(i), fx.mapper->localMap()))
                    .inserted);
  }
  const LocalMap before = fx.mapper->localMap();
  ASSERT_EQ(before.keyframes.size(), 3u);
  ASSERT_GT(before.points.size(), 100u);
  ASSERT_GT(before.lines.size(), 3u);

  const Eigen::Isometry3d C = pose(4, Eigen::Vector3d(0.3, 1, 0.2), Eigen::Vector3d(0.12, -0.05, 0.3));
  MapCorrection correction;
  correction.keyframe_id = before.reference_keyframe_id;
  correction.T_world_cam = C * before.T_world_reference;
  EXPECT_FALSE(fx.mapper->applyCorrection(MapCorrection{9999, Eigen::Isometry3d::Identity()}));
  ASSERT_TRUE(fx.mapper->applyCorrection(correction));
  const LocalMap& after = fx.mapper->localMap();
  EXPECT_GT(after.version, before.version);
  ASSERT_EQ(after.keyframes.size(), before.keyframes.size());
  for (std::size_t i = 0; i < after.keyframes.size(); ++i) {
    EXPECT_EQ(after.keyframes[i].id, before.keyframes[i].id);
    EXPECT_LT(translationError(after.keyframes[i].T_world_cam, C * before.keyframes[i].T_world_cam), 1e-9);
    EXPECT_LT(test::rotationErrorDeg(after.keyframes[i].T_world_cam, C * before.keyframes[i].T_world_cam), 1e-7);
  }
  ASSERT_EQ(after.points.size(), before.points.size());
  for (std::size_t i = 0; i < after.points.size(); ++i) {
    EXPECT_EQ(after.points[i].ref.id, before.points[i].ref.id);
    EXPECT_LT((after.points[i].P_world - C * before.points[i].P_world).norm(), 1e-9);
  }
  ASSERT_EQ(after.lines.size(), before.lines.size());
  for (std::size_t i = 0; i < after.lines.size(); ++i) {
    for (int s = 0; s < after.lines[i].num_samples; ++s) {
      EXPECT_LT((after.lines[i].samples_world[std::size_t(s)] - C * before.lines[i].samples_world[std::size_t(s)]).norm(),
                1e-9);
    }
    EXPECT_LT((after.lines[i].start_world - C * before.lines[i].start_world).norm(), 1e-9);
  }

  // The tracker built this request against the snapshot from before the correction: its pose is
  // in the old frame, and is inserted moved by C (the associations still hold).
  T = T * step;
  const auto late = trackedRequest(test::observe(scene, T), T, 3, before);
  ASSERT_LT(late->local_map_version, after.version);
  const InsertResult r = fx.mapper->insertKeyframe(*late);
  ASSERT_TRUE(r.inserted);
  EXPECT_EQ(r.ba_outliers, 0);
  EXPECT_LT(translationError(fx.mapper->localMap().T_world_reference, C * T), 1e-4);
  // A request made against the corrected snapshot is taken as it is.
  const auto current = trackedRequest(test::observe(scene, T * step), C * T * step, 4, fx.mapper->localMap());
  ASSERT_TRUE(fx.mapper->insertKeyframe(*current).inserted);
  EXPECT_LT(translationError(fx.mapper->localMap().T_world_reference, C * T * step), 1e-4);
}

}  // namespace
}  // namespace plumb

// Tracker (pipeline/odometry/tracker.h) on synthetic FrameFeatures: a seeded scene of points and
// line segments observed exactly from known poses. The map is started the way the odometry system
// does it (fillNewMapRequest -> LocalMapper::insertKeyframe -> setLocalMap -> resetAt), then the
// next frames are tracked; the recovered pose is compared with the pose the frame was made from.
#include <memory>

#include <gtest/gtest.h>

#include "pipeline/odometry/local_mapper.h"
#include "pipeline/odometry/tracker.h"
#include "tests/support/synthetic_features.h"

namespace plumb {
namespace {

using test::pose;
using test::rotationErrorDeg;
using test::translationError;

struct TrackerFixture {
  PinholeCamera camera = test::syntheticCamera();
  OdometryOptions options;
  std::unique_ptr<Tracker> tracker;
  std::unique_ptr<LocalMapper> mapper;
  std::unique_ptr<KeyframeRequest> request = std::make_unique<KeyframeRequest>();

  explicit TrackerFixture(const OdometryOptions& o = OdometryOptions()) : options(o) {
    tracker = std::make_unique<Tracker>(camera, options);
    mapper = std::make_unique<LocalMapper>(camera, options);
  }
  // As OdometrySystem::startMap.
  InsertResult startMap(const FrameFeatures& f, uint64_t sequence, const Eigen::Isometry3d& T_world_cam) {
    tracker->fillNewMapRequest(f, sequence, 0.1 * double(sequence), T_world_cam, request.get());
    const InsertResult inserted = mapper->insertKeyframe(*request);
    tracker->setLocalMap(mapper->localMap());
    tracker->resetAt(f, T_world_cam);
    return inserted;
  }
};

const Eigen::Isometry3d kStart = pose(10, Eigen::Vector3d(0.2, 1, 0.1), Eigen::Vector3d(0.5, -0.2, 0.3));
// Small inter-frame motion (~1 deg, ~2 cm): within the matcher's constant-velocity window.
const Eigen::Isometry3d kStep = pose(1.0, Eigen::Vector3d(0.3, 1, -0.2), Eigen::Vector3d(0.015, -0.008, 0.012));

TEST(Tracker, RecoversTheTruePoseOfTheNextFrameFromPoints) {
  const test::Scene scene = test::makeScene(1, 300, 0, kStart);
  TrackerFixture fx;
  const test::View first = test::observe(scene, kStart);
  ASSERT_EQ(first.features->keypoints.size(), 300u);
  const InsertResult inserted = fx.startMap(*first.features, 0, kStart);
  ASSERT_TRUE(inserted.inserted);
  ASSERT_EQ(inserted.new_points, 300);

  const Eigen::Isometry3d T_true = kStart * kStep;
  const test::View second = test::observe(scene, T_true);
  ASSERT_GT(second.features->keypoints.size(), 250u);
  const TrackResult r = fx.tracker->track(*second.features, 1, 0.1, nullptr);
  EXPECT_EQ(r.state, TrackingState::kOk);
  EXPECT_FALSE(r.used_motion_fallback);
  // The near points moved more than the constant-velocity window: the last frame gives enough
  // matches for a first pose, the local map the rest; with exact data every keypoint is an inlier.
  EXPECT_GE(r.frame_matches, fx.options.tracker.min_frame_matches);
  EXPECT_EQ(r.point_inliers, int(second.features->keypoints.size()));
  // Every inlier is a map landmark (the map was made from the first frame's points).
  EXPECT_EQ(r.landmark_inliers, r.point_inliers);
  // Exact observations: the pose is exact up to float storage of pixels and depths.
  EXPECT_LT(translationError(r.T_world_cam, T_true), 1e-4);
  EXPECT_LT(rotationErrorDeg(r.T_world_cam, T_true), 1e-3);
  // Not the starting pose (the motion is ~2 cm / 1 deg): the test would notice a tracker that
  // returned its prediction.
  EXPECT_GT(translationError(kStart, T_true), 0.015);
  EXPECT_TRUE(fx.tracker->lastPose().isApprox(r.T_world_cam, 1e-12));
}

// The velocity's per-frame covariance (covariance_local) takes motion_scale, the world covariance
// tracked_scale (docs/UNCERTAINTY.md "The motion's own scale"): changing one leaves the other
// unchanged. The synthetic camera is global shutter, so both are pure multiples of pose-only's.
TEST(Tracker, MotionScaleScalesOnlyTheVelocitysCovariance) {
  const test::Scene scene = test::makeScene(1, 300, 0, kStart);
  const test::View first = test::observe(scene, kStart);
  const test::View second = test::observe(scene, kStart * kStep);
  auto trackWith = [&](double motion_scale, double tracked_scale) {
    OdometryOptions options;
    options.uncertainty.motion_scale = motion_scale;
    options.uncertainty.tracked_scale = tracked_scale;
    TrackerFixture fx(options);
    (void)fx.startMap(*first.features, 0, kStart);
    return fx.tracker->track(*second.features, 1, 0.1, nullptr);
  };
  const TrackResult base = trackWith(1.0, 1.5);
  const TrackResult motion = trackWith(2.0, 1.5);
  const TrackResult tracked = trackWith(1.0, 3.0);
  ASSERT_TRUE(base.covariance_local_valid && base.covariance_valid);
  ASSERT_TRUE(motion.covariance_local_valid && motion.covariance_valid);
  ASSERT_TRUE(tracked.covariance_local_valid && tracked.covariance_valid);
  ASSERT_GT(base.covariance_local.trace(), 0.0);
  EXPECT_TRUE(motion.covariance_local.isApprox(2.0 * base.covariance_local, 1e-12));
  EXPECT_TRUE(motion.covariance.isApprox(base.covariance, 1e-12));
  EXPECT_TRUE(tracked.covariance_local.isApprox(base.covariance_local, 1e-12));
  EXPECT_FALSE(tracked.covariance.isApprox(base.covariance, 1e-3));
}

TEST(Tracker, FollowsASequenceWithConstantVelocity) {
  // Five frames of the same motion: from the second on the velocity prediction is exact, and the
  // per-frame poses stay on the true trajectory (no drift with exact data).
  // Started far from the world origin and turned: a velocity expressed in the wrong frame
  // (world instead of camera) would predict centimetres off here.
  const Eigen::Isometry3d start = pose(90, Eigen::Vector3d(1, 0, 0.1), Eigen::Vector3d(1.0, 2.0, -1.0));
  const test::Scene scene = test::makeScene(2, 400, 0, start, 1.5, 5.0);
  // A 3 px window: with exact data only an exact prediction finds the keypoints in it (the sparse
  // scene's unique descriptors would forgive a poor prediction in the default 15 px window).
  OdometryOptions options;
  options.matcher.points.search_radius_px = 3;
  TrackerFixture fx(options);
  const test::View first = test::observe(scene, start);
  fx.startMap(*first.features, 0, start);
  Eigen::Isometry3d T_true = start;
  for (int i = 1; i <= 5; ++i) {
    T_true = T_true * kStep;
    const test::View view = test::observe(scene, T_true);
    const TrackResult r = fx.tracker->track(*view.features, uint64_t(i), 0.1 * i, nullptr);
    ASSERT_NE(r.state, TrackingState::kLost) << "frame " << i;
    if (i >= 2) {
      // The velocity of the previous pair predicts this frame exactly: the normal window finds
      // (nearly) every keypoint of the last frame, no fallback.
      EXPECT_FALSE(r.used_motion_fallback) << "frame " << i;
      EXPECT_GE(r.frame_matches, int(0.95 * double(view.features->keypoints.size()))) << "frame " << i;
    }
    EXPECT_LT(translationError(r.T_world_cam, T_true), 2e-4) << "frame " << i;
    EXPECT_LT(rotationErrorDeg(r.T_world_cam, T_true), 2e-3) << "frame " << i;
  }
}

TEST(Tracker, RecoversThePoseFromLinesAlone) {
  // No keypoints: only line-guidance samples constrain the pose (the map starts from lines).
  const test::Scene scene = test::makeScene(3, 0, 60, kStart);
  OdometryOptions options;
  options.tracker.min_inliers_ok = 30;
  TrackerFixture fx(options);
  const test::View first = test::observe(scene, kStart);
  ASSERT_GT(first.features->lines.size(), 45u);
  const InsertResult inserted = fx.startMap(*first.features, 0, kStart);
  ASSERT_EQ(inserted.new_lines, int(first.features->lines.size()));
  ASSERT_EQ(inserted.new_points, 0);

  const Eigen::Isometry3d T_true = kStart * kStep;
  const test::View second = test::observe(scene, T_true);
  const TrackResult r = fx.tracker->track(*second.features, 1, 0.1, nullptr);
  EXPECT_EQ(r.state, TrackingState::kOk);
  EXPECT_EQ(r.point_inliers, 0);
  EXPECT_GT(r.line_inliers, 40);
  EXPECT_LT(translationError(r.T_world_cam, T_true), 1e-3);
  EXPECT_LT(rotationErrorDeg(r.T_world_cam, T_true), 1e-2);
}

TEST(Tracker, UnmatchableFrameIsLostNotPlacedSomewhere) {
  const test::Scene scene = test::makeScene(4, 300, 20, kStart);
  TrackerFixture fx;
  const test::View first = test::observe(scene, kStart);
  fx.startMap(*first.features, 0, kStart);

  // Features at plausible places with depth, but descriptors that match nothing in the map.
  const test::View unrelated = test::unrelatedView(99, 300);
  KeyframeRequest* request = fx.request.get();
  const TrackResult r = fx.tracker->track(*unrelated.features, 1, 0.1, request);
  EXPECT_EQ(r.state, TrackingState::kLost);
  EXPECT_EQ(r.frame_matches, 0);
  EXPECT_EQ(r.point_inliers + r.line_inliers, 0);
  EXPECT_FALSE(r.keyframe_requested);
  EXPECT_EQ(fx.tracker->state(), TrackingState::kLost);
  // The tracker keeps the last good frame for relocalization.
  EXPECT_TRUE(fx.tracker->lastPose().isApprox(kStart, 1e-12));
}

TEST(Tracker, FewMatchesAreWeakOrLostNeverConfidentlyWrong) {
  // Only a handful of the map's points are still seen (the rest of the frame is unrelated):
  // whatever state is reported, an ok / weak pose must be the true one.
  const test::Scene scene = test::makeScene(5, 300, 0, kStart);
  TrackerFixture fx;
  fx.startMap(*test::observe(scene, kStart).features, 0, kStart);
  const Eigen::Isometry3d T_true = kStart * kStep;
  test::Scene partial = scene;
  partial.points.resize(25);  // 25 of 300 keep their look
  const test::View seen = test::observe(partial, T_true);
  test::View frame = test::unrelatedView(7, 200);
  for (std::size_t k = 0; k < seen.features->keypoints.size(); ++k) {
    (void)frame.features->keypoints.push_back(seen.features->keypoints[k]);
    (void)frame.features->keypoint_descriptors.push_back(seen.features->keypoint_descriptors[k]);
  }
  FrameFeatures& f = *frame.features;
  f.keypoint_grid.build(int(f.keypoints.size()), [&f](int k) { return f.keypoints[k].px_undist; });

  const TrackResult r = fx.tracker->track(f, 1, 0.1, nullptr);
  EXPECT_EQ(r.state, TrackingState::kWeak);  // 25 inliers: between min_inliers_weak and _ok
  EXPECT_LE(r.point_inliers, 25);
  EXPECT_GE(r.point_inliers, 15);
  EXPECT_LT(translationError(r.T_world_cam, T_true), 1e-3);
  EXPECT_LT(rotationErrorDeg(r.T_world_cam, T_true), 1e-2);
}

TEST(Tracker, KeyframeRequestNamesTheRightLandmarks) {
  // Forced keyframe at the first tracked frame; every keypoint the request associates with a
  // landmark must be the landmark made from the same scene point.
  const test::Scene scene = test::makeScene(6, 300, 30, kStart);
  OdometryOptions options;
  options.keyframes.max_frames_between = 1;
  TrackerFixture fx(options);
  const test::View first = test::observe(scene, kStart);
  fx.startMap(*first.features, 0, kStart);
  const LocalMap& map = fx.mapper->localMap();
  ASSERT_EQ(map.points.size(), first.features->keypoints.size());

  const Eigen::Isometry3d T_true = kStart * kStep;
  const test::View second = test::observe(scene, T_true);
  auto request = std::make_unique<KeyframeRequest>();
  const TrackResult r = fx.tracker->track(*second.features, 1, 0.1, request.get());
  ASSERT_EQ(r.state, TrackingState::kOk);
  ASSERT_TRUE(r.keyframe_requested);
  EXPECT_FALSE(request->start_new_map);
  EXPECT_EQ(request->frame_sequence, 1u);
  EXPECT_EQ(request->local_map_version, map.version);
  EXPECT_TRUE(request->T_world_cam.isApprox(r.T_world_cam, 1e-12));
  ASSERT_EQ(request->features.keypoints.size(), second.features->keypoints.size());

  int associated = 0, lines_associated = 0;
  for (std::size_t k = 0; k < second.features->keypoints.size(); ++k) {
    const LandmarkRef ref = request->keypoint_landmark[k];
    if (ref.id == 0) continue;
    ++associated;
    const LocalMapPoint* lp = nullptr;
    for (const LocalMapPoint& p : map.points) {
      if (p.ref.slot == ref.slot && p.ref.id == ref.id) lp = &p;
    }
    ASSERT_NE(lp, nullptr) << "keypoint " << k << " names a landmark not in the snapshot";
    const Eigen::Vector3d truth = scene.points[std::size_t(second.keypoint_point[k])].P_world;
    EXPECT_LT((lp->P_world - truth).norm(), 1e-4) << "keypoint " << k;
  }
  for (std::size_t k = 0; k < second.features->lines.size(); ++k) {
    const LandmarkRef ref = request->line_landmark[k];
    if (ref.id == 0) continue;
    ++lines_associated;
    const LocalMapLine* ll = nullptr;
    for (const LocalMapLine& l : map.lines) {
      if (l.ref.slot == ref.slot && l.ref.id == ref.id) ll = &l;
    }
    ASSERT_NE(ll, nullptr);
    // The landmark's samples lie on the scene segment this line was observed from.
    const test::SceneLine& sl = scene.lines[std::size_t(second.line_segment[k])];
    const Eigen::Vector3d dir = (sl.B_world - sl.A_world).normalized();
    for (int s = 0; s < ll->num_samples; ++s) {
      const Eigen::Vector3d d = ll->samples_world[s] - sl.A_world;
      EXPECT_LT((d - d.dot(dir) * dir).norm(), 1e-4) << "line " << k;
    }
  }
  EXPECT_GT(associated, 250);
  EXPECT_GT(lines_associated, 15);
  // Visibility reported for culling: every local landmark the frame saw, found <= visible.
  EXPECT_GT(request->point_visibility.size(), 250u);
  for (const LandmarkVisibility& v : request->point_visibility) EXPECT_LE(v.found, v.visible);
}

TEST(Tracker, LastFrameFollowsTheCorrectionsOfANewSnapshot) {
  // ORB-SLAM2's UpdateLastFrame: when local BA moved the last frame's reference keyframe, the
  // last frame moves with it; when the last frame itself became the keyframe, it takes the
  // keyframe's refined pose; a snapshot of another map segment moves nothing.
  const test::Scene scene = test::makeScene(7, 300, 0, kStart);
  const Eigen::Isometry3d T1 = kStart * kStep;
  const Eigen::Isometry3d correction = pose(0.7, Eigen::Vector3d(1, 0.4, 0), Eigen::Vector3d(0.02, -0.01, 0.004));
  auto snapshot = std::make_unique<LocalMap>();

  for (int variant = 0; variant < 3; ++variant) {
    TrackerFixture fx;
    fx.startMap(*test::observe(scene, kStart).features, 0, kStart);
    const TrackResult r = fx.tracker->track(*test::observe(scene, T1).features, 1, 0.1, nullptr);
    ASSERT_EQ(r.state, TrackingState::kOk);
    *snapshot = fx.mapper->localMap();
    ASSERT_EQ(snapshot->keyframes.size(), 1u);
    snapshot->version += 1;
    Eigen::Isometry3d expected;
    if (variant == 0) {
      // The reference keyframe (sequence 0) moved by `correction`.
      snapshot->keyframes[0].T_world_cam = correction * kStart;
      snapshot->T_world_reference = snapshot->keyframes[0].T_world_cam;
      expected = correction * r.T_world_cam;
    } else if (variant == 1) {
      // The last frame (sequence 1) is the snapshot's reference keyframe, refined.
      snapshot->reference_keyframe_sequence = 1;
      snapshot->reference_keyframe_id = 2;
      snapshot->T_world_reference = correction * T1;
      (void)snapshot->keyframes.push_back(LocalMapKeyframe{2, snapshot->T_world_reference});
      expected = correction * T1;
    } else {
      // Another segment: same keyframe id moved, but it is not the same map.
      snapshot->segment += 1;
      snapshot->keyframes[0].T_world_cam = correction * kStart;
      expected = r.T_world_cam;
    }
    fx.tracker->setLocalMap(*snapshot);
    EXPECT_LT(translationError(fx.tracker->lastPose(), expected), 1e-9) << "variant " << variant;
    EXPECT_LT(rotationErrorDeg(fx.tracker->lastPose(), expected), 1e-7) << "variant " << variant;
    // The correction is large enough to tell apart from no correction.
    if (variant != 2) {
      EXPECT_GT(translationError(expected, r.T_world_cam), 0.01);
    }
  }
}

TEST(Tracker, ALoopCorrectionMovesLandmarksTheSnapshotDoesNotList) {
  // A loop correction moves the whole map rigidly (LocalMapper::applyCorrection). The last frame's
  // landmark associations must move with it even when the new snapshot does not list those
  // landmarks (a snapshot holds at most kMaxLocalMapPoints / kMaxLocalMapLines of the map, and
  // only the covisible neighbourhood of the reference keyframe): before the fix they kept their
  // pre-correction positions while the frame's pose and depth points moved, so the next frame was
  // tracked against a mix of two worlds several centimetres apart.
  const test::Scene scene = test::makeScene(11, 300, 40, kStart);
  const Eigen::Isometry3d T1 = kStart * kStep, T2 = T1 * kStep;
  const Eigen::Isometry3d C = pose(1.5, Eigen::Vector3d(0.2, 1, 0.3), Eigen::Vector3d(0.06, -0.04, 0.03));
  for (const bool lines_only : {false, true}) {
    TrackerFixture fx;
    const InsertResult start = fx.startMap(*test::observe(scene, kStart).features, 0, kStart);
    ASSERT_TRUE(start.inserted);
    test::View v1 = test::observe(scene, T1);
    if (lines_only) v1.features->keypoints.clear(), v1.features->keypoint_descriptors.clear();
    ASSERT_EQ(fx.tracker->track(*v1.features, 1, 0.1, nullptr).state, TrackingState::kOk);
    ASSERT_TRUE(fx.mapper->applyCorrection(MapCorrection{start.keyframe_id, C * kStart}));
    auto snapshot = std::make_unique<LocalMap>(fx.mapper->localMap());
    EXPECT_EQ(snapshot->loop_corrections, 1u);
    snapshot->points.clear();  // none of the landmarks is in the snapshot
    snapshot->lines.clear();
    fx.tracker->setLocalMap(*snapshot);
    test::View v2 = test::observe(scene, T2);
    if (lines_only) v2.features->keypoints.clear(), v2.features->keypoint_descriptors.clear();
    const TrackResult r = fx.tracker->track(*v2.features, 2, 0.2, nullptr);
    ASSERT_NE(r.state, TrackingState::kLost) << (lines_only ? "lines" : "points and lines");
    // The scene seen from T2 in the world before the correction is the corrected world's C T2.
    EXPECT_LT(translationError(r.T_world_cam, C * T2), 1e-4) << (lines_only ? "lines" : "points and lines");
    EXPECT_LT(rotationErrorDeg(r.T_world_cam, C * T2), 0.01) << (lines_only ? "lines" : "points and lines");
  }
}

}  // namespace
}  // namespace plumb

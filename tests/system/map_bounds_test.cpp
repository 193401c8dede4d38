// The map is bounded: fixed slots, retirement of the oldest keyframe, landmarks freed with their
// last observer, observation lists consistent after swap-removal; and a run long enough to fill
// the keyframe window and the point array never exceeds the capacities.
#include <gtest/gtest.h>

#include "pipeline/odometry/map.h"
#include "tests/support/odometry_run.h"

namespace plumb::test {
namespace {

KeyframePointObservation pointObs(int slot) {
  KeyframePointObservation o;
  o.point_slot = uint32_t(slot);
  return o;
}

TEST(MapBounds, KeyframeSlotsAreFixedAndLandmarksDieWithTheirLastObserver) {
  auto map = std::make_unique<Map>();
  std::vector<int> slots;
  for (std::size_t i = 0; i < kMaxMapKeyframes; ++i) slots.push_back(map->addKeyframe());
  EXPECT_EQ(map->addKeyframe(), -1);
  const int shared = map->addPoint(), own = map->addPoint();
  ASSERT_TRUE(map->addPointObservation(slots[0], pointObs(shared)));
  ASSERT_TRUE(map->addPointObservation(slots[1], pointObs(shared)));
  ASSERT_TRUE(map->addPointObservation(slots[0], pointObs(own)));
  EXPECT_FALSE(map->addPointObservation(slots[0], pointObs(own)));  // once per keyframe
  EXPECT_EQ(map->oldestKeyframeSlot(), slots[0]);
  map->removeKeyframe(slots[0]);
  EXPECT_FALSE(map->pointAlive(own));
  EXPECT_TRUE(map->pointAlive(shared));
  EXPECT_EQ(map->point(shared).observers.count(), 1);
  EXPECT_EQ(map->counts().keyframes, kMaxMapKeyframes - 1);
  EXPECT_GE(map->addKeyframe(), 0);  // the freed slot is reused
}

TEST(MapBounds, SwapRemovalKeepsObservationIndicesConsistent) {
  auto map = std::make_unique<Map>();
  const int kf = map->addKeyframe();
  std::vector<int> points;
  for (int i = 0; i < 5; ++i) {
    points.push_back(map->addPoint());
    ASSERT_TRUE(map->addPointObservation(kf, pointObs(points.back())));
  }
  map->removePoint(points[1]);
  map->removePointObservation(kf, points[3]);
  ASSERT_EQ(map->keyframe(kf).points.size(), 3u);
  for (int p : {points[0], points[2], points[4]}) {
    const uint16_t index = map->point(p).observers.obs_index[kf];
    ASSERT_LT(index, map->keyframe(kf).points.size());
    EXPECT_EQ(int(map->keyframe(kf).points[index].point_slot), p);
  }
}

TEST(MapBounds, PointArrayRefusesWhenFull) {
  auto map = std::make_unique<Map>();
  for (std::size_t i = 0; i < kMaxMapPoints; ++i) ASSERT_GE(map->addPoint(), 0);
  EXPECT_EQ(map->addPoint(), -1);
  EXPECT_EQ(map->freePointSlots(), 0u);
}

// Long enough that the keyframe window fills and keyframes retire, and the point array fills
// and the worst points are retired: counts stay within the capacities at every frame.
TEST(MapBounds, LongRunStaysWithinCapacities) {
  std::unique_ptr<SyntheticSource> source;
  ASSERT_TRUE(SyntheticSource::create(noisySynth("textured", 320), &source).ok());
  SystemOptions options = systemOptions(true);
  options.odometry.keyframes.max_frames_between = 4;  // many keyframes: the window must retire
  const OdometryRun run = runOdometry(*source, options);
  EXPECT_GT(run.stats.keyframes, uint64_t(kMaxMapKeyframes));
  EXPECT_EQ(run.max_keyframes, kMaxMapKeyframes);
  EXPECT_LE(run.max_points, kMaxMapPoints);
  EXPECT_LE(run.max_lines, kMaxMapLines);
  EXPECT_LE(run.mapper.peak.keyframes, kMaxMapKeyframes);
  EXPECT_EQ(run.stats.frames_lost, 0u);
}

}  // namespace
}  // namespace plumb::test

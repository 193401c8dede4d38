// Map::clear() (a new map segment, and the first keyframe of every run) resets what was handed out
// and nothing else: slots are handed out from 0 again as default landmarks, and a fresh map's
// landmark slots (~1.8 MiB) stay untouched (not resident) through it.
#include <gtest/gtest.h>

#include <memory>

#include "pipeline/odometry/map.h"
#include "platform/process_memory.h"

namespace plumb::test {
namespace {

TEST(MapClear, ResetsEverySlotHandedOutAndStartsAgainFromSlotZero) {
  auto map = std::make_unique<Map>();
  const int kf = map->addKeyframe();
  ASSERT_GE(kf, 0);
  for (int i = 0; i < 300; ++i) {
    const int slot = map->addPoint();
    ASSERT_EQ(slot, i);
    map->point(slot).P_world = Eigen::Vector3d(1, 2, 3);
    map->point(slot).ref_octave = 5;
    KeyframePointObservation o;
    o.point_slot = uint32_t(slot);
    ASSERT_TRUE(map->addPointObservation(kf, o));
  }
  for (int i = 0; i < 40; ++i) {
    const int slot = map->addLine();
    ASSERT_EQ(slot, i);
    map->line(slot).num_samples = 5;
  }
  map->removePoint(7);  // a freed slot below the high-water mark
  map->clear();
  EXPECT_EQ(map->counts().keyframes, 0u);
  EXPECT_EQ(map->counts().points, 0u);
  EXPECT_EQ(map->counts().lines, 0u);
  EXPECT_EQ(map->freePointSlots(), kMaxMapPoints);
  EXPECT_EQ(map->freeLineSlots(), kMaxMapLines);
  for (int i = 0; i < 300; ++i) EXPECT_FALSE(map->pointAlive(i));
  for (int i = 0; i < 40; ++i) EXPECT_FALSE(map->lineAlive(i));
  // Everything written before clear() is gone from the slots (not only the ids).
  for (int i = 0; i < 300; ++i) {
    EXPECT_EQ(map->point(i).P_world, Eigen::Vector3d::Zero()) << i;
    EXPECT_EQ(map->point(i).ref_octave, 0) << i;
    EXPECT_EQ(map->point(i).observers.count(), 0) << i;
  }
  for (int i = 0; i < 40; ++i) EXPECT_EQ(map->line(i).num_samples, 0) << i;
  EXPECT_EQ(map->addPoint(), 0);
  EXPECT_EQ(map->addLine(), 0);
  const int kf2 = map->addKeyframe();
  ASSERT_GE(kf2, 0);
  EXPECT_EQ(map->keyframe(kf2).points.size(), 0u);
  // A second clear() right after the first finds only what the second segment handed out.
  map->clear();
  EXPECT_EQ(map->freePointSlots(), kMaxMapPoints);
}

TEST(MapClear, AFreshMapStaysUnresidentThroughClear) {
  long peak_kib = 0, before_kib = 0, after_kib = 0;
  auto map = std::make_unique<Map>();
  ASSERT_TRUE(readRss(&peak_kib, &before_kib));
  map->clear();
  ASSERT_TRUE(readRss(&peak_kib, &after_kib));
  const double landmark_mib = (kMaxMapPoints * sizeof(MapPoint) + kMaxMapLines * sizeof(MapLine)) / 1048576.0;
  std::printf("landmark slots %.1f MiB; RSS grew %ld KiB through clear()\n", landmark_mib, after_kib - before_kib);
  ASSERT_GT(landmark_mib, 1.0);
  EXPECT_LT(after_kib - before_kib, 512);  // the whole landmark array (1.8 MiB) and a page or more of every keyframe slot before
}

}  // namespace
}  // namespace plumb::test

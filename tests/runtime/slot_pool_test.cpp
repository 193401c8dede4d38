#include "runtime/slot_pool.h"

#include <gtest/gtest.h>

#include <set>
#include <thread>

namespace plumb::runtime {
namespace {

TEST(SlotPool, HandsOutEverySlotOnceThenReportsNone) {
  SlotPool<int> pool(3);
  std::set<SlotIndex> seen;
  SlotIndex index = 0;
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(pool.tryAcquire(&index));
    EXPECT_LT(index, 3u);
    EXPECT_TRUE(seen.insert(index).second) << "slot handed out twice";
  }
  EXPECT_FALSE(pool.tryAcquire(&index));
  EXPECT_EQ(pool.freeCount(), 0u);
  pool.release(1);
  ASSERT_TRUE(pool.tryAcquire(&index));
  EXPECT_EQ(index, 1u);
}

TEST(SlotPool, SlotsAreCreatedOnceAndKeepTheirAddresses) {
  SlotPool<std::array<double, 64>> pool(4);
  const auto* first = &pool[0];
  SlotIndex index = 0;
  for (int round = 0; round < 10; ++round) {
    ASSERT_TRUE(pool.tryAcquire(&index));
    pool[index][0] = round;
    pool.release(index);
  }
  EXPECT_EQ(first, &pool[0]);
  EXPECT_EQ(pool.size(), 4u);
  EXPECT_EQ(pool.freeCount(), 4u);
}

TEST(SlotPool, ThreadedCirculationKeepsOwnershipExclusive) {
  // The source acquires and writes a slot, the sink checks and releases it: a slot written by
  // both at once, or lost, shows up as a wrong value or a hang.
  constexpr int kFrames = 20'000;
  SlotPool<uint64_t> pool(4);
  SpscRing<SlotIndex> to_sink(8);
  int wrong = 0;
  std::thread sink([&] {
    for (int received = 0; received < kFrames;) {
      SlotIndex index = 0;
      if (!to_sink.try_pop(index)) {
        std::this_thread::yield();
        continue;
      }
      wrong += pool[index] != static_cast<uint64_t>(received);
      ++received;
      pool.release(index);
    }
  });
  for (int frame = 0; frame < kFrames; ++frame) {
    SlotIndex index = 0;
    pool.releasedBell().waitUntil([&] { return pool.tryAcquire(&index); });
    pool[index] = static_cast<uint64_t>(frame);
    while (!to_sink.try_push(index)) std::this_thread::yield();
  }
  sink.join();
  EXPECT_EQ(wrong, 0);
  EXPECT_EQ(pool.freeCount(), 4u);
}

}  // namespace
}  // namespace plumb::runtime

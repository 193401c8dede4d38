#include "runtime/spsc_ring.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <thread>

namespace plumb::runtime {
namespace {

// Counts every construction and destruction so tests can prove the ring neither leaks nor
// double-destroys elements, and that moves are used where promised.
struct Tracked {
  static inline int constructed = 0;
  static inline int destroyed = 0;
  static inline int copies = 0;
  static inline int moves = 0;
  static void reset() { constructed = destroyed = copies = moves = 0; }

  int value = 0;
  bool moved_from = false;
  explicit Tracked(int v = 0) : value(v) { ++constructed; }
  Tracked(const Tracked& other) : value(other.value) { ++constructed; ++copies; }
  Tracked(Tracked&& other) noexcept : value(other.value) {
    ++constructed;
    ++moves;
    other.moved_from = true;
  }
  Tracked& operator=(const Tracked& other) {
    value = other.value;
    ++copies;
    return *this;
  }
  Tracked& operator=(Tracked&& other) noexcept {
    value = other.value;
    other.moved_from = true;
    ++moves;
    return *this;
  }
  ~Tracked() { ++destroyed; }
};

TEST(SpscRing, CapacityIsRoundedUpToAPowerOfTwo) {
  EXPECT_EQ(SpscRing<int>(1).capacity(), 1u);
  EXPECT_EQ(SpscRing<int>(5).capacity(), 8u);
  EXPECT_EQ(SpscRing<int>(8).capacity(), 8u);
  EXPECT_EQ(SpscRing<int>(0).capacity(), 1u);
}

TEST(SpscRing, FullAndEmptyEdges) {
  SpscRing<int> ring(4);
  int out = -1;
  EXPECT_TRUE(ring.empty());
  EXPECT_FALSE(ring.try_pop(out));
  EXPECT_EQ(ring.front(), nullptr);
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(ring.try_push(i));
  EXPECT_TRUE(ring.full());
  EXPECT_FALSE(ring.try_push(99));  // every cell is usable, the fifth push fails
  EXPECT_EQ(ring.sizeApprox(), 4u);
  ASSERT_NE(ring.front(), nullptr);
  EXPECT_EQ(*ring.front(), 0);
  ASSERT_TRUE(ring.try_pop(out));
  EXPECT_EQ(out, 0);
  EXPECT_TRUE(ring.try_push(4));  // one cell free again
  for (int expected = 1; expected <= 4; ++expected) {
    ASSERT_TRUE(ring.try_pop(out));
    EXPECT_EQ(out, expected);
  }
  EXPECT_TRUE(ring.empty());
  EXPECT_FALSE(ring.try_pop(out));
}

TEST(SpscRing, WrapsAroundManyTimesInOrder) {
  SpscRing<uint32_t> ring(8);
  uint32_t next_in = 0;
  uint32_t next_out = 0;
  // Uneven push/pop bursts so the indices cross the end of the buffer at every phase.
  for (int round = 0; round < 1000; ++round) {
    const int pushes = 1 + round % 7;
    for (int i = 0; i < pushes && !ring.full(); ++i) ASSERT_TRUE(ring.try_push(next_in++));
    const int pops = 1 + (round * 5) % 6;
    for (int i = 0; i < pops; ++i) {
      uint32_t out = 0;
      if (!ring.try_pop(out)) break;
      ASSERT_EQ(out, next_out++);
    }
  }
  uint32_t out = 0;
  while (ring.try_pop(out)) ASSERT_EQ(out, next_out++);
  EXPECT_EQ(next_in, next_out);
  EXPECT_GT(next_in, 3000u);
}

TEST(SpscRing, ElementLifetimesBalanceAndMovesAreUsed) {
  Tracked::reset();
  {
    SpscRing<Tracked> ring(4);
    EXPECT_EQ(Tracked::constructed, 0);  // storage is raw: no element exists before a push
    Tracked a(1);
    ASSERT_TRUE(ring.try_push(a));  // copy
    EXPECT_FALSE(a.moved_from);
    ASSERT_TRUE(ring.try_push(Tracked(2)));  // move
    ASSERT_TRUE(ring.try_push(Tracked(3)));
    EXPECT_EQ(Tracked::copies, 1);
    EXPECT_EQ(Tracked::moves, 2);
    Tracked out;
    ASSERT_TRUE(ring.try_pop(out));
    EXPECT_EQ(out.value, 1);
    EXPECT_EQ(Tracked::moves, 3);  // popping moves out
    // Elements 2 and 3 are still inside when the ring is destroyed.
  }
  EXPECT_EQ(Tracked::constructed, Tracked::destroyed);
}

TEST(SpscRing, EveryPoppedElementIsDestroyedExactlyOnce) {
  Tracked::reset();
  {
    SpscRing<Tracked> ring(2);
    for (int i = 0; i < 100; ++i) {
      ASSERT_TRUE(ring.try_push(Tracked(i)));
      Tracked out;
      ASSERT_TRUE(ring.try_pop(out));
      ASSERT_EQ(out.value, i);
    }
    // Per iteration: temporary + cell + out, all gone at scope end.
    EXPECT_EQ(Tracked::constructed - Tracked::destroyed, 0);
  }
  EXPECT_EQ(Tracked::constructed, Tracked::destroyed);
}

TEST(SpscRing, HoldsMoveOnlyTypes) {
  SpscRing<std::unique_ptr<int>> ring(2);
  ASSERT_TRUE(ring.try_push(std::make_unique<int>(5)));
  std::unique_ptr<int> out;
  ASSERT_TRUE(ring.try_pop(out));
  ASSERT_NE(out, nullptr);
  EXPECT_EQ(*out, 5);
}

TEST(SpscRing, IndicesLiveOnSeparateCacheLines) {
  // The ring object is cache-line aligned and spans at least producer + consumer lines.
  EXPECT_EQ(alignof(SpscRing<int>) % kCacheLineBytes, 0u);
  EXPECT_GE(sizeof(SpscRing<int>), 2 * kCacheLineBytes);
}

TEST(SpscRing, ThreadedProducerConsumerChecksum) {
  constexpr uint64_t kItems = 1'000'000;
  SpscRing<uint64_t> ring(1024);
  uint64_t consumer_sum = 0;
  uint64_t consumer_order_errors = 0;
  std::thread consumer([&] {
    uint64_t expected = 0;
    while (expected < kItems) {
      uint64_t v = 0;
      if (!ring.try_pop(v)) {
        std::this_thread::yield();
        continue;
      }
      if (v != expected) ++consumer_order_errors;
      consumer_sum += v * 2654435761u;
      ++expected;
    }
  });
  uint64_t producer_sum = 0;
  for (uint64_t i = 0; i < kItems; ++i) {
    while (!ring.try_push(i)) std::this_thread::yield();
    producer_sum += i * 2654435761u;
  }
  consumer.join();
  EXPECT_EQ(consumer_order_errors, 0u);
  EXPECT_EQ(consumer_sum, producer_sum);
  EXPECT_TRUE(ring.empty());
}

TEST(SpscRing, ThreadedHandOffPublishesTheElementContents) {
  // Payload written by the producer must be fully visible to the consumer (release/acquire).
  struct Block {
    uint64_t words[8];
  };
  constexpr int kBlocks = 100'000;
  SpscRing<Block> ring(64);
  int bad = 0;
  std::thread consumer([&] {
    for (int received = 0; received < kBlocks;) {
      Block b{};
      if (!ring.try_pop(b)) {
        std::this_thread::yield();
        continue;
      }
      for (uint64_t w : b.words) bad += w != static_cast<uint64_t>(received);
      ++received;
    }
  });
  for (int i = 0; i < kBlocks; ++i) {
    Block b;
    for (uint64_t& w : b.words) w = static_cast<uint64_t>(i);
    while (!ring.try_push(b)) std::this_thread::yield();
  }
  consumer.join();
  EXPECT_EQ(bad, 0);
}

}  // namespace
}  // namespace plumb::runtime

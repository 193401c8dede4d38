#include "runtime/latest_snapshot.h"

#include <gtest/gtest.h>

#include <array>
#include <thread>

namespace plumb::runtime {
namespace {

struct FakeMap {
  std::array<uint64_t, 64> landmark_ids{};
};

TEST(LatestSnapshot, ReaderSeesNothingBeforeTheFirstPublish) {
  LatestSnapshot<FakeMap> channel;
  uint64_t version = 0;
  EXPECT_EQ(channel.acquireLatest(&version), nullptr);
  EXPECT_EQ(version, LatestSnapshot<FakeMap>::kNoVersion);
}

TEST(LatestSnapshot, ReaderGetsTheNewestAndKeepsItUntilSomethingNewer) {
  LatestSnapshot<FakeMap> channel;
  for (uint64_t v = 1; v <= 3; ++v) {
    channel.writeBuffer().landmark_ids.fill(v);
    channel.publish(v);
  }
  uint64_t version = 0;
  const FakeMap* map = channel.acquireLatest(&version);
  ASSERT_NE(map, nullptr);
  EXPECT_EQ(version, 3u);  // 1 and 2 were superseded before the reader looked
  EXPECT_EQ(map->landmark_ids[10], 3u);
  EXPECT_EQ(channel.acquireLatest(&version), map);  // nothing new: same buffer
  EXPECT_EQ(version, 3u);
  channel.writeBuffer().landmark_ids.fill(4);
  channel.publish(4);
  map = channel.acquireLatest(&version);
  EXPECT_EQ(version, 4u);
  EXPECT_EQ(map->landmark_ids[63], 4u);
}

TEST(LatestSnapshot, ThreadedReaderNeverSeesATornSnapshotAndVersionsOnlyGrow) {
  LatestSnapshot<FakeMap> channel;
  constexpr uint64_t kPublishes = 100'000;
  int torn = 0;
  int went_back = 0;
  std::thread reader([&] {
    uint64_t last = 0;
    for (;;) {
      uint64_t version = 0;
      const FakeMap* map = channel.acquireLatest(&version);
      if (map == nullptr) continue;
      for (uint64_t id : map->landmark_ids) torn += id != version;
      went_back += version < last;
      last = version;
      if (version == kPublishes) return;
    }
  });
  for (uint64_t v = 1; v <= kPublishes; ++v) {
    channel.writeBuffer().landmark_ids.fill(v);  // the writer rewrites the whole buffer
    channel.publish(v);
  }
  reader.join();
  EXPECT_EQ(torn, 0);
  EXPECT_EQ(went_back, 0);
  EXPECT_EQ(channel.publishedVersion(), kPublishes);
}

}  // namespace
}  // namespace plumb::runtime

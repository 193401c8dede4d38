// HelperThread: runBoth() runs one part on the caller and one on a second thread, and returns
// with both parts' writes visible; the thread is started once, on first use, and joined on
// destruction. (Run under ThreadSanitizer with the rest of tests/runtime.)
#include "runtime/helper_thread.h"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

namespace plumb::runtime {
namespace {

TEST(HelperThread, BothPartsRunAndTheirWritesAreVisibleAfterwards) {
  HelperThread helper;
  constexpr int kRounds = 2000;
  std::vector<int> here_out(kRounds, -1), there_out(kRounds, -1);
  for (int i = 0; i < kRounds; ++i) {
    helper.runBoth([&] { here_out[i] = i; }, [&] { there_out[i] = 2 * i; });
    ASSERT_EQ(here_out[i], i);
    ASSERT_EQ(there_out[i], 2 * i);  // written on the helper, read here without a lock
  }
}

TEST(HelperThread, ThereRunsOnOneOtherThreadStartedOnce) {
  const std::thread::id caller = std::this_thread::get_id();
  HelperThread helper;
  std::thread::id first, here_id;
  helper.runBoth([&] { here_id = std::this_thread::get_id(); }, [&] { first = std::this_thread::get_id(); });
  EXPECT_EQ(here_id, caller);
  EXPECT_NE(first, caller);
  for (int i = 0; i < 50; ++i) {
    std::thread::id there_id;
    helper.runBoth([] {}, [&] { there_id = std::this_thread::get_id(); });
    EXPECT_EQ(there_id, first);  // the same thread every time
  }
}

TEST(HelperThread, HalvesOfARowLoopGiveTheOneThreadResult) {
  constexpr int kRows = 480, kCols = 640;
  std::vector<float> one(kRows * kCols), two(kRows * kCols);
  auto rows = [&](std::vector<float>& out, int begin, int end) {
    for (int y = begin; y < end; ++y)
      for (int x = 0; x < kCols; ++x) out[y * kCols + x] = static_cast<float>(x * 0.37 + y * 1.91) / (1.0f + y);
  };
  rows(one, 0, kRows);
  HelperThread helper;
  helper.runBoth([&] { rows(two, 0, kRows / 2); }, [&] { rows(two, kRows / 2, kRows); });
  EXPECT_EQ(one, two);
}

TEST(HelperThread, AStartedJobFinishesBeforeTheNextRunBoth) {
  HelperThread helper;
  struct Job {
    std::vector<int> out = std::vector<int>(100000, 0);
    static void run(void* self) {
      for (int& v : static_cast<Job*>(self)->out) v = 7;
    }
  } job;
  ASSERT_TRUE(helper.startJob(&Job::run, &job));
  int sum_seen_by_there = 0;
  helper.runBoth([] {}, [&] { sum_seen_by_there = job.out.front() + job.out.back(); });
  EXPECT_EQ(sum_seen_by_there, 14);  // the job was done before runBoth's part began
  for (int v : job.out) ASSERT_EQ(v, 7);
}

TEST(HelperThread, DestructionWithoutUseAndAfterUseReturns) {
  { HelperThread unused; }
  {
    HelperThread used;
    int n = 0;
    used.runBoth([] {}, [&] { n = 1; });
    EXPECT_EQ(n, 1);
  }  // joins the thread
  SUCCEED();
}

}  // namespace
}  // namespace plumb::runtime

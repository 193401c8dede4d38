#include "platform/allocation_counter.h"

#include <gtest/gtest.h>

#include <memory>
#include <thread>
#include <vector>

namespace plumb {
namespace {

TEST(AllocationCounter, CountsHeapAllocations) {
  AllocationScope scope;
  auto p = std::make_unique<int>(3);
  std::vector<double> v(100);
  EXPECT_GE(scope.count(), 2u);
  EXPECT_EQ(*p, 3);
  EXPECT_EQ(v.size(), 100u);
}

TEST(AllocationCounter, StackWorkIsNotCounted) {
  AllocationScope scope;
  int sum = 0;
  for (int i = 0; i < 1000; ++i) sum += i;
  EXPECT_EQ(sum, 499500);
  EXPECT_EQ(scope.count(), 0u);
}

// A thread excluded from the count (a viewer's server thread) allocates into its own counter:
// the main count does not move, the excluded one does, and other threads still count.
TEST(AllocationCounter, AnExcludedThreadCountsApart) {
  const uint64_t excluded_before = excludedAllocationCount();
  uint64_t counted_on_thread = 0;
  std::thread worker([&] {
    excludeThisThreadFromAllocationCount();
    const uint64_t before = allocationCount();
    std::vector<std::unique_ptr<int>> v;
    for (int i = 0; i < 50; ++i) v.push_back(std::make_unique<int>(i));
    counted_on_thread = allocationCount() - before;
  });
  worker.join();
  // Other threads may allocate meanwhile (gtest does not), but never 50 times by themselves.
  EXPECT_LT(counted_on_thread, 50u);
  EXPECT_GE(excludedAllocationCount() - excluded_before, 50u);
  AllocationScope scope;
  auto p = std::make_unique<int>(1);
  EXPECT_GE(scope.count(), 1u);  // this thread was never excluded
}

}  // namespace
}  // namespace plumb

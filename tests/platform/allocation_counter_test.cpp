#include "platform/allocation_counter.h"

#include <gtest/gtest.h>

#include <memory>
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

}  // namespace
}  // namespace plumb

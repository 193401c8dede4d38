#include "platform/fixed_vector.h"

#include <gtest/gtest.h>

namespace plumb {
namespace {

TEST(FixedVector, PushUntilFullThenRefuses) {
  FixedVector<int, 3> v;
  EXPECT_TRUE(v.push_back(1));
  EXPECT_TRUE(v.push_back(2));
  EXPECT_TRUE(v.push_back(3));
  EXPECT_TRUE(v.full());
  EXPECT_FALSE(v.push_back(4));
  EXPECT_EQ(v.size(), 3u);
  EXPECT_EQ(v[2], 3);
  v.clear();
  EXPECT_TRUE(v.empty());
  EXPECT_NE(v.emplace_back(), nullptr);
  EXPECT_EQ(v.size(), 1u);
}

}  // namespace
}  // namespace plumb

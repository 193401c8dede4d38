#include "pipeline/frontend/round_half_away.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include <gtest/gtest.h>

namespace plumb {
namespace {

float floatFromBits(uint32_t bits) {
  float x = 0.0f;
  std::memcpy(&x, &bits, sizeof x);
  return x;
}

// Rounding can only go wrong next to a half or an integer: every float within 16 ulps of each
// k + 0.5 and each k (|k| up to 2^16, then sparser up to 2^31), every 4,099th float pattern from 0
// to 2^32 elsewhere, and the edges: 2^20..2^40 and their neighbours, infinity and NaN.
TEST(RoundHalfAwayFromZero, EqualsLroundf) {
  long checked = 0;
  auto expect_same = [&](float x) {
    ASSERT_EQ(roundHalfAwayFromZero(x), std::lround(x)) << "x = " << x;
    ASSERT_EQ(roundHalfAwayFromZero(-x), std::lround(-x)) << "x = " << -x;
    ++checked;
  };
  auto around = [&](float centre) {
    float below = centre, above = centre;
    expect_same(centre);
    for (int i = 0; i < 16; ++i) {
      below = std::nextafter(below, 0.0f);
      above = std::nextafter(above, 2.0f * centre + 1.0f);
      expect_same(below);
      expect_same(above);
    }
  };
  for (long k = 0; k < (1L << 31); k = k < (1L << 16) ? k + 1 : k + k / 1024) {
    around(static_cast<float>(k) + 0.5f);
    around(static_cast<float>(k));
  }
  for (uint32_t bits = 0; bits < 0x4F800000u; bits += 4099) expect_same(floatFromBits(bits));
  for (int e = 20; e <= 40; ++e) around(std::ldexp(1.0f, e));
  expect_same(0.49999997f);  // x + 0.5 would round up to 1: the classic wrong shortcut
  expect_same(std::numeric_limits<float>::denorm_min());
  EXPECT_GT(checked, 1000000);
  // Outside long's range and NaN libm decides: the helper hands those to std::lround.
  EXPECT_EQ(roundHalfAwayFromZero(std::numeric_limits<float>::infinity()),
            std::lround(std::numeric_limits<float>::infinity()));
  EXPECT_EQ(roundHalfAwayFromZero(std::numeric_limits<float>::quiet_NaN()),
            std::lround(std::numeric_limits<float>::quiet_NaN()));
}

}  // namespace
}  // namespace plumb

#pragma once
// std::lround for floats, inline. libm's lroundf is a call of ~27 instructions and the front end
// rounds ~4,300 coordinates and angles a frame with it (issue 22's instruction budget); this is
// ~8 and returns the same value for every float (tests/pipeline/frontend/round_half_away_test.cpp
// compares it with std::lround next to every integer and half up to 2^16, sparser to 2^31, on a
// sweep of all magnitudes and at the edges).
#include <cmath>

namespace plumb {

inline long roundHalfAwayFromZero(float x) {
  // Truncation is exact below 2^30, and so is x - t: the fraction is a multiple of x's ulp and
  // smaller than 1. Beyond that (and for NaN) libm decides, as before.
  if (!(std::fabs(x) < 0x1p30f)) return std::lround(x);
  const long t = static_cast<long>(x);
  const float fraction = x - static_cast<float>(t);
  return t + (fraction >= 0.5f ? 1 : 0) - (fraction <= -0.5f ? 1 : 0);
}

}  // namespace plumb

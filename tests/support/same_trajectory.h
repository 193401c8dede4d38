#pragma once
// sameTrajectory(a, b): two trajectories equal bit for bit (timestamps, validity, every pose entry),
// i.e. what the bytes of their trajectory files depend on; the first difference otherwise.
#include <gtest/gtest.h>

#include <vector>

#include "sensor/stamped_pose.h"

namespace plumb::test {

// Exactly equal, bit for bit (what the trajectory file's bytes depend on).
inline ::testing::AssertionResult sameTrajectory(const std::vector<StampedPose>& a, const std::vector<StampedPose>& b) {
  if (a.size() != b.size()) return ::testing::AssertionFailure() << a.size() << " vs " << b.size() << " frames";
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].timestamp != b[i].timestamp || a[i].valid != b[i].valid ||
        !(a[i].T_world_cam.matrix().array() == b[i].T_world_cam.matrix().array()).all()) {
      return ::testing::AssertionFailure() << "frame " << i << " differs: t " << a[i].timestamp << " position "
                                           << a[i].T_world_cam.translation().transpose() << " vs "
                                           << b[i].T_world_cam.translation().transpose();
    }
  }
  return ::testing::AssertionSuccess();
}

}  // namespace plumb::test

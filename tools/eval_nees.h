#pragma once
// `plumb eval --nees`: reads the covariance files, computes NEES against ground truth
// (drivers/trajectory/evaluate_nees.h) and prints it (text, or the JSON members `nees_per_dof`
// and `nees`). Kept apart from cmd_eval.cpp, which only calls it.
#include <string>
#include <vector>

#include "drivers/trajectory/evaluate_nees.h"
#include "platform/status.h"

namespace plumb::tools {

// Up to two files (a keyframe and a tracked one, either order; the kind comes from each file's
// header). `estimate` gives the gauge anchor (its first valid pose).
Status evaluateNeesFiles(const std::vector<StampedPose>& ground_truth, const std::vector<StampedPose>& estimate,
                         const std::vector<std::string>& covariance_paths, NeesResult* out);

void printNeesText(const NeesResult& nees);
// `"nees_per_dof": {...}, "nees": {...}` without braces around them (members of eval's object).
std::string neesJsonMembers(const NeesResult& nees);

}  // namespace plumb::tools

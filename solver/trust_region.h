#pragma once
// The Levenberg-Marquardt trust region both of our nonlinear least-squares solvers step with
// (local BA, solver/local_ba_solve.cpp; the pose graph, solver/pose_graph_solve.cpp): the damping
// is lambda = 1 / radius, and after each trial step the radius follows the gain ratio
//   quality = (actual cost decrease) / (decrease the quadratic model predicted)
// with Nielsen's rule (the one Ceres uses): an accepted step scales the radius by
// 1 / max(1/3, 1 - (2 quality - 1)^3), i.e. up to 3x for a step the model predicted well and down
// for a poor one; a rejected step divides it by a factor that doubles with every rejection in a row.
// Capped at the solver's max_trust_radius. Plain arithmetic, so both solvers' results do not depend
// on which of them owns the code.
#include <algorithm>
#include <cmath>

namespace plumb {

class TrustRegion {
 public:
  TrustRegion(double initial_radius, double max_radius) : radius_(initial_radius), max_radius_(max_radius) {}

  double lambda() const { return 1.0 / radius_; }

  // actual / predicted, or -1 when the model predicts no decrease (the step is then rejected).
  static double stepQuality(double actual_decrease, double predicted_decrease) {
    return predicted_decrease > 0.0 ? actual_decrease / predicted_decrease : -1.0;
  }

  void stepAccepted(double step_quality) {
    const double grow = 1.0 - std::pow(2.0 * step_quality - 1.0, 3);
    radius_ = std::min(max_radius_, radius_ / std::max(1.0 / 3.0, grow));
    decrease_factor_ = 2.0;
  }

  void stepRejected() {
    radius_ /= decrease_factor_;
    decrease_factor_ *= 2.0;
  }

 private:
  double radius_;
  double max_radius_;
  double decrease_factor_ = 2.0;
};

}  // namespace plumb

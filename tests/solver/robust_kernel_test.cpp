#include "solver/robust_kernel.h"

#include <gtest/gtest.h>

namespace plumb {
namespace {

// rho' and rho'' against central differences of rho and rho', on both sides of the Huber kink.
void checkDerivatives(const RobustKernel& kernel, double s) {
  const double h = 1e-6 * std::max(1.0, s);
  const RobustKernelValue k = evaluateKernel(kernel, s);
  const double rho1_numeric = (evaluateKernel(kernel, s + h).rho - evaluateKernel(kernel, s - h).rho) / (2.0 * h);
  const double rho2_numeric = (evaluateKernel(kernel, s + h).rho1 - evaluateKernel(kernel, s - h).rho1) / (2.0 * h);
  EXPECT_NEAR(k.rho1, rho1_numeric, 1e-7 * std::max(1.0, std::abs(k.rho1))) << "s = " << s;
  EXPECT_NEAR(k.rho2, rho2_numeric, 1e-6 * std::max(1e-3, std::abs(k.rho2))) << "s = " << s;
  EXPECT_EQ(kernelWeight(kernel, s), k.rho1);
}

TEST(RobustKernel, PseudoHuberDerivatives) {
  for (double delta : {0.5, 1.0, 2.4477}) {
    for (double s : {1e-4, 0.3, 1.0, 5.0, 40.0, 1e4}) checkDerivatives({RobustKernelType::kPseudoHuber, delta}, s);
  }
}

TEST(RobustKernel, HuberDerivativesAwayFromTheKink) {
  for (double delta : {1.0, 2.7955}) {
    for (double s : {1e-3, 0.5 * delta * delta, 2.0 * delta * delta, 100.0, 1e5}) {
      checkDerivatives({RobustKernelType::kHuber, delta}, s);
    }
  }
}

TEST(RobustKernel, QuadraticNearZeroLinearFarAway) {
  const RobustKernel pseudo{RobustKernelType::kPseudoHuber, 2.0};
  const RobustKernel huber{RobustKernelType::kHuber, 2.0};
  const RobustKernel none{RobustKernelType::kNone, 2.0};
  EXPECT_NEAR(evaluateKernel(pseudo, 1e-6).rho, 1e-6, 1e-12);
  EXPECT_DOUBLE_EQ(evaluateKernel(huber, 1.0).rho, 1.0);
  EXPECT_DOUBLE_EQ(evaluateKernel(none, 123.0).rho, 123.0);
  EXPECT_DOUBLE_EQ(evaluateKernel(none, 123.0).rho1, 1.0);
  // Far away both grow like 2 delta |e| (s = e^2): Huber exactly, Pseudo-Huber asymptotically.
  const double e = 1e4;
  EXPECT_DOUBLE_EQ(evaluateKernel(huber, e * e).rho, 2.0 * 2.0 * e - 4.0);
  EXPECT_NEAR(evaluateKernel(pseudo, e * e).rho / (2.0 * 2.0 * e), 1.0, 1e-3);
  // The IRLS weight falls off like delta / |e|.
  EXPECT_NEAR(evaluateKernel(pseudo, e * e).rho1 * e / 2.0, 1.0, 1e-3);
  EXPECT_DOUBLE_EQ(evaluateKernel(huber, e * e).rho1, 2.0 / e);
}

TEST(RobustKernel, PseudoHuberMatchesItsClosedForm) {
  const double delta = 1.5;
  const double s = 7.0;
  EXPECT_NEAR(evaluateKernel({RobustKernelType::kPseudoHuber, delta}, s).rho,
              2.0 * delta * delta * (std::sqrt(1.0 + s / (delta * delta)) - 1.0), 1e-14);
}

}  // namespace
}  // namespace plumb

namespace plumb {
namespace {

// robustCost (the LM loops' cost-only form) is evaluateKernel's rho bit for bit: local BA's
// step acceptance compares costs, so a different rounding would change trajectories.
TEST(RobustKernel, CostOnlyFormEqualsEvaluateKernelRhoExactly) {
  for (const RobustKernelType type : {RobustKernelType::kNone, RobustKernelType::kHuber, RobustKernelType::kPseudoHuber}) {
    for (const double delta : {0.5, 1.9598, 2.4477, 2.7955}) {
      const RobustKernel kernel{type, delta};
      for (double s = 0.0; s < 400.0; s = s * 1.37 + 1e-3) {
        ASSERT_EQ(robustCost(kernel, s), evaluateKernel(kernel, s).rho)
            << static_cast<int>(type) << " delta " << delta << " s " << s;
      }
      ASSERT_EQ(robustCost(kernel, delta * delta), evaluateKernel(kernel, delta * delta).rho);  // the kink
    }
  }
}

}  // namespace
}  // namespace plumb

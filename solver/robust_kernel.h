#pragma once
// Robust kernels rho(s) of the SQUARED Mahalanobis norm s = e^T Omega e (Ceres / g2o convention),
// so the robust cost of a residual is 0.5 * rho(s) and the quadratic cost is rho(s) = s.
//
//   Pseudo-Huber (the paper's):  rho(s) = 2 delta^2 (sqrt(1 + s / delta^2) - 1)
//                                rho'   = 1 / sqrt(1 + s / delta^2)
//                                rho''  = -rho'^3 / (2 delta^2)
//   Huber:                       rho(s) = s                          for s <= delta^2
//                                       = 2 delta sqrt(s) - delta^2  otherwise
//                                rho'   = min(1, delta / sqrt(s)),   rho'' = -rho' / (2 s) beyond
//
// Both behave like s near 0 and grow like 2 delta |e| for large errors, so an outlier pulls with
// a bounded force. Pseudo-Huber is smooth (C-infinity), which keeps Gauss-Newton well behaved.
// Pseudo-Huber equals Ceres' SoftLOneLoss(delta), Huber equals Ceres' HuberLoss(delta).
//
// The IRLS weight is rho'(s): minimising sum 0.5 rho(s_i) by Gauss-Newton with the weighted
// normal equations J^T (rho' Omega) J dx = -J^T (rho' Omega) e (g2o's choice; the rho'' term is
// dropped so the approximate Hessian stays positive semi-definite).
#include <cmath>

namespace plumb {

enum class RobustKernelType { kNone, kHuber, kPseudoHuber };

struct RobustKernel {
  RobustKernelType type = RobustKernelType::kPseudoHuber;
  double delta = 1.0;  // in units of the whitened residual (sqrt of a chi-square value)
};

struct RobustKernelValue {
  double rho = 0.0;   // rho(s)
  double rho1 = 1.0;  // rho'(s)   (= IRLS weight)
  double rho2 = 0.0;  // rho''(s)
};

inline RobustKernelValue evaluateKernel(const RobustKernel& kernel, double s) {
  RobustKernelValue out;
  const double d2 = kernel.delta * kernel.delta;
  switch (kernel.type) {
    case RobustKernelType::kNone:
      out.rho = s;
      break;
    case RobustKernelType::kPseudoHuber: {
      const double root = std::sqrt(1.0 + s / d2);
      out.rho = 2.0 * d2 * (root - 1.0);
      out.rho1 = 1.0 / root;
      out.rho2 = -out.rho1 * out.rho1 * out.rho1 / (2.0 * d2);
      break;
    }
    case RobustKernelType::kHuber:
      if (s <= d2) {
        out.rho = s;
      } else {
        const double root = std::sqrt(s);
        out.rho = 2.0 * kernel.delta * root - d2;
        out.rho1 = kernel.delta / root;
        out.rho2 = -out.rho1 / (2.0 * s);
      }
      break;
  }
  return out;
}

// rho(s) alone, for the cost evaluations of the LM loops: the same operations as evaluateKernel's
// rho (so the same bits; tests/solver/robust_kernel_test.cpp compares them), without rho' and rho''.
inline double robustCost(const RobustKernel& kernel, double s) {
  const double d2 = kernel.delta * kernel.delta;
  switch (kernel.type) {
    case RobustKernelType::kNone:
      return s;
    case RobustKernelType::kPseudoHuber:
      return 2.0 * d2 * (std::sqrt(1.0 + s / d2) - 1.0);
    case RobustKernelType::kHuber:
      return s <= d2 ? s : 2.0 * kernel.delta * std::sqrt(s) - d2;
  }
  return s;
}

// rho(s) and the IRLS weight rho'(s) only, for the hot loops: skips rho'' and one division.
inline void robustCostAndWeight(const RobustKernel& kernel, double s, double* rho, double* weight) {
  const double d2 = kernel.delta * kernel.delta;
  switch (kernel.type) {
    case RobustKernelType::kNone:
      *rho = s;
      *weight = 1.0;
      return;
    case RobustKernelType::kPseudoHuber: {
      const double root = std::sqrt(1.0 + s / d2);
      *rho = 2.0 * d2 * (root - 1.0);
      *weight = 1.0 / root;
      return;
    }
    case RobustKernelType::kHuber:
      break;
  }
  if (s <= d2) {
    *rho = s;
    *weight = 1.0;
  } else {
    const double root = std::sqrt(s);
    *rho = 2.0 * kernel.delta * root - d2;
    *weight = kernel.delta / root;
  }
}

// The IRLS weight alone (rho'(s)).
inline double kernelWeight(const RobustKernel& kernel, double s) { return evaluateKernel(kernel, s).rho1; }

}  // namespace plumb

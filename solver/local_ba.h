#pragma once
// Bounded-window local bundle adjustment with a hand-written dense Schur complement.
//
// VARIABLES. K optimised keyframe poses T_cam_world (6-dof left perturbation, solver/se3.h) and
// L landmarks P_world (3-dof; map points and line-guidance points alike). Fixed keyframes
// contribute residuals but no variables: they hold the gauge. Without any fixed keyframe the
// problem has a 6-dof gauge freedom; LM damping still gives steps, but covariance() then fails.
// Line residuals carry no depth: a line sample's depth comes from a stereo observation in the
// keyframe that back-projected it (its anchor: noise_model.h lineSampleAnchorInformation, added
// by the local mapper); a window constrained by unanchored lines alone also needs a second fixed
// keyframe to fix its scale.
//
// COST. 0.5 * sum_obs rho(e^T Omega e) with the factors of solver/factors.h (stereo [u,v,u_r],
// mono [u,v], line sample l^T pi(T P)) and the kernels of solver/robust_kernel.h. Each iteration
// linearises with IRLS weights w = rho'(s), giving the normal equations H dx = -g:
//
//          6K          3L
//       +--------+-----------------+        H_pp: block diagonal (one 6x6 per keyframe: every
//   6K  |  H_pp  |      H_pl       |              observation touches exactly one pose)
//       +--------+-----------------+        H_pl: one 6x3 block W_ij per observation (i, j)
//   3L  |  H_lp  |  H_ll (3x3 diag)|        H_ll: block diagonal, one 3x3 per landmark
//       +--------+-----------------+
//
// SCHUR COMPLEMENT. Eliminating the landmarks (cheap: H_ll is block diagonal) leaves the reduced
// camera system of size 6K:
//
//   S  = H_pp - H_pl H_ll^-1 H_lp,        S_ik = [i==k] H_ii - sum_j W_ij H_jj^-1 W_kj^T
//   S dx_p = -(g_p - H_pl H_ll^-1 g_l)
//   dx_l_j = -H_jj^-1 (g_l_j + sum_i W_ij^T dx_p_i)        (back-substitution per landmark)
//
// S is dense 6K x 6K (every pair of keyframes sharing a landmark couples) and small (60 x 60 for
// K = 10), so it is factorised by a dense in-place Cholesky (solver/dense_cholesky.h). Only its
// lower block triangle is formed: each unordered pair of a landmark's observations once.
//
// LEVENBERG-MARQUARDT. The damped system adds lambda * clamp(diag(H), 1e-6, 1e32) to the diagonal
// of BOTH H_pp and H_ll before elimination (Ceres' schedule: lambda = 1 / trust radius, radius
// grown by 1 / max(1/3, 1 - (2 rho - 1)^3) on success and shrunk by a doubling factor on failure).
// A rejected step re-eliminates from the stored linearisation without re-evaluating residuals.
//
// DEGENERATE LANDMARKS. Each 3x3 block is inverted by Cholesky when well conditioned, otherwise
// by a pseudo-inverse on its range (eigenvalues above landmark_singular_threshold * the largest).
// That is exact, not a hack: a line-guidance point seen only on lines can slide along its 3D line
// without changing any residual, so the null direction of H_ll is also a null direction of H_lp;
// it gets no step and carries no pose information. A zero or non-finite block (every observation
// behind the camera, a point at a camera centre) holds the landmark fixed for that linearisation.
// Nothing produces Inf or NaN. Observations with the point behind the camera (Z <= 0) are dropped
// from the linearisation, and flagged outliers when still behind at the end of solve().
//
// COVARIANCE (paper eq. 12). At the current estimate, undamped, with the same IRLS weights:
//   C = (H_A - H_B H_C^-1 H_B^T)^-1 = S^-1,   H_A = H_pp, H_B = H_pl, H_C = H_ll,
// the joint covariance of the K optimised poses (landmarks marginalised). covariance(kf) is the
// 6x6 diagonal block; fullCovariance() the whole 6K x 6K matrix, rows/cols ordered by
// poseVariableIndex(). Rank-deficient H_C blocks enter through their pseudo-inverse (above).
//
// MEMORY. reserve() allocates every buffer once for the given maxima; add*(), solve(),
// computeCovariance() and computeStep() never touch the heap (proved by a test hooking operator
// new). Buffers: per keyframe (pose, 6x6 H_pp block, g_p, pose step), per landmark (point,
// 3x3 H_ll, its Cholesky inverse, g_l, step, first-observation offset), per observation (kind,
// z, Omega, W_ij = J_pose^T w Omega J_point, V_ij = W_ij H_jj^-1, chi2), the landmark-major
// observation order plus one landmark's scratch list, one dense S and one dense covariance of
// the maximal 6K x 6K size, used through their top-left corners.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "solver/outlier_thresholds.h"
#include "solver/point_space_blocks.h"
#include "solver/camera_intrinsics.h"
#include "solver/robust_kernel.h"
#include "solver/types.h"
#include "solver/variance_factor.h"
#include "solver/zero_page_allocator.h"

namespace plumb {

enum class ObservationKind : uint8_t { kStereoPoint, kMonoPoint, kLineSample };

struct LocalBaOptions {
  int max_iterations = 10;  // LM iterations (accepted and rejected steps both count)
  RobustKernelType kernel = RobustKernelType::kPseudoHuber;
  // Kernel widths per residual dimension (whitened units; sqrt of 95% chi-square quantiles).
  double kernel_delta_stereo = 2.7955;  // sqrt(7.815)
  double kernel_delta_mono = 2.4477;    // sqrt(5.991)
  double kernel_delta_line = 1.9598;    // sqrt(3.841)
  // Chi-square thresholds for the outlier flags written after solve() (for map culling).
  OutlierChi2 chi2;  // outlier thresholds by error dof (solver/outlier_thresholds.h)
  double initial_trust_radius = 1e4;  // lambda = 1 / radius
  double max_trust_radius = 1e16;
  double min_relative_decrease = 1e-3;  // accept a step when actual / predicted exceeds this
  // Stop when |cost change| / cost of an accepted step falls below this (0: run all iterations).
  double function_tolerance = 1e-6;
  // Eigenvalues of a 3x3 landmark block below this fraction of its largest one are treated as
  // exact zeros (pseudo-inverse; see DEGENERATE LANDMARKS above).
  double landmark_singular_threshold = 1e-10;
  // computeCovariance() refuses the covariance when, for some pose variable k, C_kk * H_kk exceeds
  // this: H_kk is the variable's own information (everything else known), 1 / C_kk its marginal
  // information (landmarks and other poses eliminated), so the product says how much of the
  // information the elimination cancelled (a variance inflation factor, independent of units).
  // The cancellation is computed in floating point with an error of ~1e-13 of H_kk: a direction
  // the observations do not fix leaves a pivot of that size and EITHER sign. Measured: genuine
  // windows reach 2.8e7 (synth:office_loop:1 with noise; head250 2.7e6), a window with a null
  // direction 5e13 (synth:fast_rotation:1 noise-free, where the sign came out positive and one
  // keyframe published 1e7-3e9 m^2/rad^2 against 1e-7 for its neighbours). At 1e9 a marginal is
  // still ~1e4 times its rounding error. docs/UNCERTAINTY.md "A degenerate window".
  double covariance_max_variance_inflation = 1e9;

  RobustKernel kernelFor(ObservationKind kind) const {
    return {kernel, kind == ObservationKind::kStereoPoint ? kernel_delta_stereo
                    : kind == ObservationKind::kMonoPoint ? kernel_delta_mono
                                                          : kernel_delta_line};
  }
  double chi2ThresholdFor(ObservationKind kind) const {
    return kind == ObservationKind::kStereoPoint ? chi2.stereo
           : kind == ObservationKind::kMonoPoint ? chi2.mono
                                                 : chi2.line;
  }
};

// Scales on the model's information by residual kind, for computeCovariance(): the reciprocals of
// the variance components the residuals support (LocalBundleAdjuster::varianceComponents).
struct InformationScales {
  double pixel = 1.0;  // points' [u, v] (stereo and mono)
  double depth = 1.0;  // stereo points' disparity u - u_r
  double line = 1.0;   // line samples' distance to the 2D line
};

// A posteriori variance components of the points' two noise sources (solver/variance_factor.h):
// pixel detection and depth, each the model's noise times its own factor.
struct PointVarianceComponents {
  double pixel = 1.0;
  double depth = 1.0;
  double redundancy = 0.0;  // of the point residuals, shared by the two in proportion to their dof
};

enum class LocalBaStatus {
  kConverged,            // function_tolerance reached
  kMaxIterations,        // ran max_iterations (the usual outcome in a real-time window)
  kNoVariables,          // nothing to optimise (no free keyframe and no landmark)
  kLinearSolverFailed,   // S not positive definite even with damping (covariance: gauge free)
};

struct LocalBaSummary {
  LocalBaStatus status = LocalBaStatus::kNoVariables;
  int iterations = 0;
  int successful_steps = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int num_outliers = 0;          // observations above their chi-square threshold at the end
  int num_fixed_landmarks = 0;   // landmarks held fixed as degenerate in the last linearisation
  bool ok() const { return status == LocalBaStatus::kConverged || status == LocalBaStatus::kMaxIterations; }
};

const char* toString(LocalBaStatus status);

class LocalBundleAdjuster {
 public:
  static constexpr int kDefaultMaxKeyframes = 10;  // optimised keyframes (plus fixed ones)

  // Allocates all buffers. max_keyframes counts fixed and optimised keyframes together.
  void reserve(int max_keyframes, int max_landmarks, int max_observations);
  void setCamera(const CameraIntrinsics& camera) { camera_ = camera; }
  // Forget keyframes, landmarks and observations; keeps the reserved memory.
  void clear();

  // Each add returns the new index, or -1 when the reserved capacity is full, an index is out
  // of range or an input is not finite (nothing is added then).
  int addKeyframe(const Eigen::Isometry3d& T_cam_world, bool fixed);
  int addLandmark(const Eigen::Vector3d& P_world);
  int addStereoPointObservation(int keyframe, int landmark, const Eigen::Vector3d& z_uvr,
                                const Eigen::Matrix3d& information);
  int addMonoPointObservation(int keyframe, int landmark, const Eigen::Vector2d& z_uv,
                              const Eigen::Matrix2d& information);
  // `line` normalised ([a, b, c], a^2 + b^2 = 1, see normalizeLine()).
  int addLineObservation(int keyframe, int landmark, const Eigen::Vector3d& line, double information);
  // Disabled observations are ignored by solve() and covariance (e.g. after outlier culling).
  void setObservationEnabled(int observation, bool enabled);

  // Levenberg-Marquardt from the current estimate; updates poses and landmarks in place and the
  // per-observation chi2 / outlier flags at the end.
  LocalBaSummary solve(const LocalBaOptions& options);

  // Linearise at the current estimate (undamped) and compute C = S^-1. Returns false when S is
  // not positive definite (e.g. no fixed keyframe, or a keyframe without constraints), or
  // numerically singular (options.covariance_max_variance_inflation).
  // `scales` multiply the information of each residual kind in that linearisation only (the
  // variance components of docs/UNCERTAINTY.md; the solution is not touched).
  bool computeCovariance(const LocalBaOptions& options, const InformationScales& scales = InformationScales());
  Matrix6d covariance(int keyframe) const;  // zero for fixed keyframes
  Eigen::Block<const Eigen::MatrixXd> fullCovariance() const;
  int numPoseVariables() const { return num_pose_variables_; }
  int poseVariableIndex(int keyframe) const { return keyframes_[keyframe].variable; }  // -1: fixed

  int numKeyframes() const { return num_keyframes_; }
  int numLandmarks() const { return num_landmarks_; }
  int numObservations() const { return num_observations_; }
  const Eigen::Isometry3d& pose(int keyframe) const { return keyframes_[keyframe].T_cam_world; }
  const Eigen::Vector3d& landmark(int landmark) const { return landmarks_[landmark].P_world; }
  double observationChi2(int observation) const { return observations_[observation].chi2; }
  // solve()'s chi-square classification at its final estimate (updateOutlierFlags; also behind the
  // camera). computeCovariance() and computeStep() leave it as it is.
  bool isOutlier(int observation) const { return observations_[observation].outlier; }
  double cost(const LocalBaOptions& options) const;  // robust cost at the current estimate
  // A posteriori variance factor sigma0^2 (solver/variance_factor.h) of the inliers after solve():
  // redundancy = inlier error dof - 6 per optimised pose - per landmark min(its inlier error dof,
  // 3 for a point, 2 for a line sample: its slide along the line is unobservable, 3 when its
  // anchor observation pins that slide).
  // Read it before computeCovariance(), which may re-linearise (and so re-evaluate the chi2
  // values; the outlier flags stay solve()'s). local_ba_variance.cpp.
  double varianceFactor(const LocalBaOptions& options) const;
  // Variance components of the POINT residuals after solve() (before computeCovariance(), like
  // varianceFactor): the stereo residual [u, v, u_r] is split into its pixel part [u, v] and its
  // depth part, the disparity u - u_r, in which the model's information is block diagonal (the
  // two are independent sensors: corner detection and the depth camera), and each part's inlier
  // chi2 is divided by its share of the points' redundancy (error dof - 6 per optimised pose - 3
  // per point landmark, shared in proportion to the parts' dof: a point seen V times has 2V - 2
  // pixel and V - 1 depth redundancy). Line samples are left out, their anchor observations too:
  // see docs/UNCERTAINTY.md (their residuals cannot show their noise). A part whose redundancy is below min_redundancy gets 1.
  PointVarianceComponents varianceComponents(const LocalBaOptions& options, int min_redundancy = 30) const;

  // Diagnostics (tests): linearise at the current estimate and solve ONE damped step with the
  // given lambda, without applying it. Returns false if the damped S is not positive definite.
  bool computeStep(const LocalBaOptions& options, double lambda);
  Vector6d poseStep(int keyframe) const;
  Eigen::Vector3d landmarkStep(int landmark) const;

 private:
  struct Keyframe {
    Eigen::Isometry3d T_cam_world = Eigen::Isometry3d::Identity();
    Eigen::Isometry3d T_candidate = Eigen::Isometry3d::Identity();
    Matrix6d H_pose = Matrix6d::Zero();  // undamped diagonal block of H_pp
    Vector6d g_pose = Vector6d::Zero();
    Vector6d step = Vector6d::Zero();
    PoseNormalAccumulator normal;  // H_pose / g_pose as they are summed (free keyframes)
    int variable = -1;  // index into the reduced system; -1 when fixed
  };
  struct Landmark {
    Eigen::Vector3d P_world = Eigen::Vector3d::Zero();
    Eigen::Vector3d P_candidate = Eigen::Vector3d::Zero();
    Eigen::Matrix3d H_point = Eigen::Matrix3d::Zero();      // undamped H_ll block
    Eigen::Matrix3d H_point_inv = Eigen::Matrix3d::Zero();  // damped inverse of the last elimination
    Eigen::Vector3d g_point = Eigen::Vector3d::Zero();
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    Eigen::Vector3d damping = Eigen::Vector3d::Zero();  // LM damping of H_ll's diagonal, last elimination
    int first_observation = 0;  // into observation_order_ (landmark-major order)
    int num_observations = 0;
    bool eliminated = false;  // false: held fixed in the current linearisation
  };
  struct Observation {
    Eigen::Vector3d z = Eigen::Vector3d::Zero();  // [u,v,u_r] | [u,v,-] | line [a,b,c]
    Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
    Matrix63d W = Matrix63d::Zero();  // J_pose^T w Omega J_point
    // W H_point_inv, except for line samples in a landmark seen only by line samples (all of
    // them, as the local mapper builds its problems): their W is rank one, W = u r^T with
    // u = [w J^T; P_cam x w J^T] (6) and r = R^T J^T (3), and the elimination only needs u, r and
    // H_point_inv r, kept here as columns 0, 1 (top) and 2 (top); see solveDamped.
    Matrix63d V = Matrix63d::Zero();
    double chi2 = 0.0;
    int keyframe = 0;
    int landmark = 0;
    ObservationKind kind = ObservationKind::kStereoPoint;
    bool enabled = true;
    bool valid = false;  // point in front of the camera at the last linearisation
    bool outlier = false;
  };

  int addObservation(int keyframe, int landmark, ObservationKind kind, const Eigen::Vector3d& z,
                     const Eigen::Matrix3d& information);
  void buildStructure();
  bool isLineSample(const Landmark& landmark) const;  // observed by a line-sample residual
  // IRLS normal equations at the current estimate into the per-keyframe / per-landmark /
  // per-observation blocks; returns the robust cost of the valid observations.
  double linearize(const LocalBaOptions& options);
  // Eliminates the landmarks, factorises the damped S in S_ and solves for the pose step; with
  // back_substitute (the LM loop, computeStep) also writes every keyframe's and landmark's step.
  bool solveDamped(const LocalBaOptions& options, double lambda, bool back_substitute = true);
  bool evaluateChi2(const Observation& obs, const Eigen::Isometry3d& T_cam_world,
                    const Eigen::Vector3d& P_world, double* chi2) const;
  double candidateCost(const LocalBaOptions& options, bool* all_valid) const;
  double modelCostReduction(double lambda) const;
  void updateOutlierFlags(const LocalBaOptions& options, LocalBaSummary* summary);

  CameraIntrinsics camera_;
  std::vector<Keyframe> keyframes_;
  // Zero pages as for the observations below: all-zero bytes ARE a default Landmark (zero
  // matrices, counts 0, false), so this only defers residency to the first BA that reaches a slot.
  std::vector<Landmark, ZeroPageAllocator<Landmark>> landmarks_;
  // Reserved for the worst case, written from the front: untouched slots stay out of RSS.
  std::vector<Observation, ZeroPageAllocator<Observation>> observations_;
  std::vector<int> observation_order_;  // observation indices grouped by landmark
  std::vector<int> landmark_scratch_;   // one landmark's observations in free keyframes: variables
  std::vector<Observation*> landmark_scratch_obs_;  // ... and the observations
  std::vector<const double*> landmark_scratch_u_;   // a run of line-sample landmarks' u (solveDamped)
  std::vector<int> variable_keyframe_;  // pose variable -> keyframe
  Eigen::MatrixXd S_;                   // reduced camera system / its Cholesky factor
  Eigen::VectorXd rhs_;                 // right-hand side / pose step of the reduced system
  Eigen::MatrixXd covariance_;          // S^-1 (undamped) after computeCovariance()
  int num_keyframes_ = 0;
  int num_landmarks_ = 0;
  int num_observations_ = 0;
  int num_pose_variables_ = 0;
  int num_fixed_landmarks_ = 0;
  bool covariance_valid_ = false;
  // The stored linearisation (blocks, IRLS weights, valid flags) is at the current estimate and
  // the observation set has not changed since: computeCovariance() can eliminate from it.
  bool linearized_at_estimate_ = false;
  bool structure_built_ = false;  // observation_order_ and the landmarks' ranges match the problem
  InformationScales information_scales_;  // computeCovariance's; all 1 while solving
};

}  // namespace plumb

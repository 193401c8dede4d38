#pragma once
// In-place dense Cholesky for the reduced camera system. Eigen's LLT would do the maths, but
// its storage follows the matrix size, and the window size changes from call to call; working in
// place on the top-left corner of a buffer reserved once keeps solve() free of heap allocation.
#include <Eigen/Core>

namespace plumb {

// Overwrites the lower triangle of the symmetric matrix A (only its lower triangle is read) with
// L, A = L L^T. Returns false (A partly overwritten) when a pivot is not positive.
bool choleskyInPlace(Eigen::Ref<Eigen::MatrixXd> A);

// Solves L L^T x = b in place (b -> x) with the factor from choleskyInPlace().
void choleskySolveInPlace(const Eigen::Ref<const Eigen::MatrixXd>& L, Eigen::Ref<Eigen::VectorXd> b);

// Writes (L L^T)^-1 into inverse (same size as L; symmetric, both triangles filled).
void choleskyInverse(const Eigen::Ref<const Eigen::MatrixXd>& L, Eigen::Ref<Eigen::MatrixXd> inverse);

}  // namespace plumb

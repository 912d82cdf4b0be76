#pragma once
// Cholesky factorisation of a small symmetric positive definite matrix of fixed size, read from
// its lower triangle, for the exact manifold finish (manifold_polish.h): its 6 x 6 normal
// equations and effective inverse mass (3 x 3 in 2-D), a few of each per pair update.
//
// Why not Eigen::LLT: on these fixed 6 x 6 matrices Eigen runs its general unblocked loop with
// run-time bounds; here the sizes are compile-time constants and the pivots' reciprocals are kept
// so that the solves multiply. Eigen's LLT calls were 15 % of a short-schedule pyramid_20 step;
// this one made the step about 2 % faster (docs/benchmarks.md, "Exact finish before the first
// sweep"): most of that time is the pivots' dependent square roots, which both pay.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace monolith::solvers::contact {

template <int n>
class SmallCholesky {
 public:
  using Matrix = Eigen::Matrix<double, n, n>;
  using Vector = Eigen::Matrix<double, n, 1>;

  // A = L L^T from A's lower triangle. False if a pivot is not positive (or NaN): A is not
  // positive definite to rounding.
  bool compute(const Matrix& a) {
    for (int j = 0; j < n; ++j) {
      double pivot = a(j, j);
      for (int k = 0; k < j; ++k) pivot -= l_[j][k] * l_[j][k];
      if (!(pivot > 0)) return false;
      l_[j][j] = std::sqrt(pivot);
      inverseRoot_[j] = 1 / l_[j][j];
      for (int i = j + 1; i < n; ++i) {
        double v = a(i, j);
        for (int k = 0; k < j; ++k) v -= l_[i][k] * l_[j][k];
        l_[i][j] = v * inverseRoot_[j];
      }
    }
    return true;
  }
  // True if the smallest diagonal entry of L exceeds `ratio` times the largest: a test of rank
  // (the square roots of the pivots scale like the singular values' roots).
  bool wellConditioned(double ratio) const {
    double lo = l_[0][0], hi = l_[0][0];
    for (int j = 1; j < n; ++j) lo = std::min(lo, l_[j][j]), hi = std::max(hi, l_[j][j]);
    return lo > ratio * hi;
  }
  // A^{-1} b (after a successful compute).
  Vector solve(const Vector& b) const {
    double y[n];
    for (int i = 0; i < n; ++i) {
      double v = b[i];
      for (int k = 0; k < i; ++k) v -= l_[i][k] * y[k];
      y[i] = v * inverseRoot_[i];
    }
    Vector x;
    for (int i = n - 1; i >= 0; --i) {
      double v = y[i];
      for (int k = i + 1; k < n; ++k) v -= l_[k][i] * x[k];
      x[i] = v * inverseRoot_[i];
    }
    return x;
  }

 private:
  double l_[n][n] = {};
  double inverseRoot_[n] = {};
};

}  // namespace monolith::solvers::contact

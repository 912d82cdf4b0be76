#pragma once
// Cholesky (L D L^T) factorisation of a small symmetric positive definite matrix of fixed size,
// read from its lower triangle, for the exact manifold finish (manifold_polish.h): its 6 x 6 normal
// equations and effective inverse mass (3 x 3 in 2-D), a few of each per pair update.
//
// Why not Eigen::LLT: on these fixed 6 x 6 matrices Eigen runs its general unblocked loop with
// run-time bounds; here the sizes are compile-time constants and the pivots' reciprocals are kept
// so that the solves multiply. Measured on a short-schedule pyramid_20 step, where Eigen's LLT
// takes 15 % of the time: an L L^T written so makes the step about 2 % faster, and this L D L^T,
// which keeps the square roots off the pivots' dependent chain, another 6 %.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace monolith::solvers::contact {

template <int n>
class SmallCholesky {
 public:
  using Matrix = Eigen::Matrix<double, n, n>;
  using Vector = Eigen::Matrix<double, n, 1>;

  // A = L D L^T from A's lower triangle (unit L, no square roots on the pivots' dependent
  // chain). False if a pivot is not positive (or NaN): A is not positive definite to rounding.
  bool compute(const Matrix& a) {
    for (int j = 0; j < n; ++j) {
      double pivot = a(j, j);
      for (int k = 0; k < j; ++k) pivot -= l_[j][k] * ld_[j][k];
      if (!(pivot > 0)) return false;
      pivot_[j] = pivot;
      inversePivot_[j] = 1 / pivot;
      for (int i = j + 1; i < n; ++i) {
        double v = a(i, j);
        for (int k = 0; k < j; ++k) v -= l_[i][k] * ld_[j][k];
        ld_[i][j] = v;  // L(i, j) D(j)
        l_[i][j] = v * inversePivot_[j];
      }
    }
    return true;
  }
  // The same on a positive semi-definite A (a Gram matrix of rows), dropping every row whose
  // pivot is at most `ratio`^2 times its diagonal entry: a row within an angle of about `ratio`
  // of the span of the rows before it. solve() then leaves its unknown at 0, so the result
  // solves the independent rows; whether it also meets the dropped ones is for the caller to
  // check. Returns the number of rows dropped.
  int computeDroppingDependent(const Matrix& a, double ratio) {
    int dropped = 0;
    for (int j = 0; j < n; ++j) {
      double pivot = a(j, j);
      for (int k = 0; k < j; ++k) pivot -= l_[j][k] * ld_[j][k];
      const bool keep = pivot > ratio * ratio * a(j, j);
      dropped += keep ? 0 : 1;
      pivot_[j] = keep ? pivot : 0.0;
      inversePivot_[j] = keep ? 1 / pivot : 0.0;
      for (int i = j + 1; i < n; ++i) {
        double v = 0;
        if (keep) {
          v = a(i, j);
          for (int k = 0; k < j; ++k) v -= l_[i][k] * ld_[j][k];
        }
        ld_[i][j] = v;
        l_[i][j] = v * inversePivot_[j];
      }
    }
    return dropped;
  }
  // True if the smallest pivot exceeds `ratio`^2 times the largest: a test of rank (the
  // pivots scale like the singular values; `ratio` is on their square roots, as for L L^T).
  bool wellConditioned(double ratio) const {
    double lo = pivot_[0], hi = pivot_[0];
    for (int j = 1; j < n; ++j) lo = std::min(lo, pivot_[j]), hi = std::max(hi, pivot_[j]);
    return lo > ratio * ratio * hi;
  }
  // A^{-1} b (after a successful compute).
  Vector solve(const Vector& b) const {
    double y[n];
    for (int i = 0; i < n; ++i) {
      double v = b[i];
      for (int k = 0; k < i; ++k) v -= l_[i][k] * y[k];
      y[i] = v;
    }
    Vector x;
    for (int i = n - 1; i >= 0; --i) {
      double v = y[i] * inversePivot_[i];
      for (int k = i + 1; k < n; ++k) v -= l_[k][i] * x[k];
      x[i] = v;
    }
    return x;
  }

 private:
  // L and L D both: the factorisation's inner products take L(i, k) L(j, k) D(k) as l_ times
  // ld_, one multiply each, and the solves read l_ alone (144 more numbers on the stack). No
  // initial values: the factorisations write every entry that is read (the strict lower
  // triangles and the pivots), and zeroing them cost about 1 % of a pyramid step (a few
  // factorisations per pair update).
  double l_[n][n], ld_[n][n];
  double pivot_[n], inversePivot_[n];
};

}  // namespace monolith::solvers::contact

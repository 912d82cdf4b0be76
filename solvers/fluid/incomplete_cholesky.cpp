// IC(0) / MIC(0) (see incomplete_cholesky.h).
#include "solvers/fluid/incomplete_cholesky.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace monolith::solvers {

IncompleteCholesky::IncompleteCholesky(const SparseMatrixR& A, double modification) {
  if (A.rows() != A.cols()) throw std::invalid_argument("IncompleteCholesky: matrix must be square");
  if (modification < 0 || modification > 1) throw std::invalid_argument("IncompleteCholesky: modification in [0, 1]");
  const int n = static_cast<int>(A.rows());
  // Column k of the lower triangle = row k of the upper triangle (symmetry).
  start_.assign(n + 1, 0);
  std::vector<double> original(n, 0.0), work(n, 0.0);
  for (int k = 0; k < n; ++k) {
    for (SparseMatrixR::InnerIterator it(A, k); it; ++it) {
      if (it.col() > k) {
        rows_.push_back(static_cast<int>(it.col()));
        values_.push_back(it.value());
      } else if (it.col() == k) {
        original[k] = it.value();
      }
    }
    start_[k + 1] = static_cast<int>(rows_.size());
  }
  work = original;
  diagonal_.assign(n, 0.0);
  for (int k = 0; k < n; ++k) {
    double pivot = work[k];
    if (!(pivot >= 0.25 * original[k]) || !(pivot > 0)) {
      pivot = original[k] > 0 ? original[k] : 1.0;
      ++safeguarded_;
    }
    const double lkk = std::sqrt(pivot);
    diagonal_[k] = lkk;
    const int b = start_[k], e = start_[k + 1];
    for (int t = b; t < e; ++t) values_[t] /= lkk;
    // Schur update of the trailing matrix restricted to the pattern: S_ij -= L_ik L_jk.
    for (int s = b; s < e; ++s) {
      const int j = rows_[s];
      const double ljk = values_[s];
      work[j] -= ljk * ljk;
      for (int t = s + 1; t < e; ++t) {
        const int i = rows_[t];  // i > j: entry (i, j) lives in column j
        const double update = values_[t] * ljk;
        const auto first = rows_.begin() + start_[j], last = rows_.begin() + start_[j + 1];
        const auto hit = std::lower_bound(first, last, i);
        if (hit != last && *hit == i) {
          values_[hit - rows_.begin()] -= update;
        } else if (modification > 0) {
          // MIC: keep the row sums of rows i and j by moving the dropped fill to their diagonals.
          work[i] -= modification * update;
          work[j] -= modification * update;
        }
      }
    }
  }
  // Row-wise copy of L (transpose of the column storage), in increasing column order per row.
  rowStart_.assign(n + 1, 0);
  for (int r : rows_) ++rowStart_[r + 1];
  for (int i = 0; i < n; ++i) rowStart_[i + 1] += rowStart_[i];
  rowCols_.resize(rows_.size());
  rowValues_.resize(rows_.size());
  std::vector<int> fill(rowStart_.begin(), rowStart_.end() - 1);
  for (int k = 0; k < n; ++k)
    for (int t = start_[k]; t < start_[k + 1]; ++t) {
      const int slot = fill[rows_[t]]++;
      rowCols_[slot] = k;
      rowValues_[slot] = values_[t];
    }
}

void IncompleteCholesky::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const {
  const int n = size();
  z = r;
  // Forward: L y = r (row oriented, gather).
  for (int i = 0; i < n; ++i) {
    double s = z[i];
    for (int t = rowStart_[i]; t < rowStart_[i + 1]; ++t) s -= rowValues_[t] * z[rowCols_[t]];
    z[i] = s / diagonal_[i];
  }
  // Backward: L^T z = y (row k of L^T is column k of L).
  for (int k = n - 1; k >= 0; --k) {
    double s = z[k];
    for (int t = start_[k]; t < start_[k + 1]; ++t) s -= values_[t] * z[rows_[t]];
    z[k] = s / diagonal_[k];
  }
}

}  // namespace monolith::solvers

#pragma once
// Incomplete Cholesky preconditioners for the assembled pressure Poisson block G^T beta^-1 G
// (notes 4.4: the thesis code preconditions the pressure block with IC(0)).
//
//  * IC(0): L L^T ~ A with L restricted to the sparsity of the lower triangle of A; fill outside
//    that pattern is dropped.
//  * MIC(0): the dropped fill is instead subtracted from the diagonal of both rows it belongs to
//    (scaled by `modification`, the usual 0.97), so L L^T matches A's row sums on smooth vectors;
//    this cuts the iteration count from O(n) to about O(sqrt n) on Poisson problems.
//
// Pivot safeguard: if an updated pivot falls below 1/4 of A's diagonal (always possible for MIC on
// singular pure-Neumann matrices, whose last pivot of a closed region tends to zero), the original
// diagonal is used instead. The factor stays SPD, which is all CG needs.
//
// The factorization is right-looking over columns; the two triangular solves are sequential (they
// are inherently ordered) and therefore deterministic on any thread count.
#include "solvers/fluid/operators.h"

#include <vector>

namespace monolith::solvers {

class IncompleteCholesky {
 public:
  IncompleteCholesky() = default;
  // A: symmetric, row-major; only the upper triangle (= lower by symmetry) and diagonal are read.
  // modification = 0: IC(0); 0.97: MIC(0).
  IncompleteCholesky(const SparseMatrixR& A, double modification);

  // z = (L L^T)^-1 r
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const;
  int size() const { return static_cast<int>(diagonal_.size()); }
  int safeguardedPivots() const { return safeguarded_; }

 private:
  // Column k of L below the diagonal: rows_[start_[k] .. start_[k+1]) (sorted) and values_
  // (used by the factorization and, as rows of L^T, by the backward solve).
  std::vector<int> start_, rows_;
  std::vector<double> values_;
  // Row i of L left of the diagonal (gather-form forward solve: better locality than scattering).
  std::vector<int> rowStart_, rowCols_;
  std::vector<double> rowValues_;
  std::vector<double> diagonal_;  // L_kk
  int safeguarded_ = 0;
};

}  // namespace monolith::solvers

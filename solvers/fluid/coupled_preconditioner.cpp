// Preconditioners of the coupled system (5.31); see coupled_preconditioner.h.
#include "solvers/fluid/coupled_preconditioner.h"

#include "solvers/fluid/spd_systems.h"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace monolith::solvers {

std::string toString(CoupledPreconditionerKind kind) {
  switch (kind) {
    case CoupledPreconditionerKind::BlockDiagonal: return "block_diagonal";
    case CoupledPreconditionerKind::CutCorrected: return "cut_corrected";
  }
  return "?";
}

namespace {

// The unknowns of z a velocity unknown's column of K touches, with K's coefficients:
// A = sum over velocity unknowns v of beta_v^-1 k_v k_v^T (+ I on the viscous rows).
template <int d>
void faceColumn(const FluidOperators<d>& ops, int v, std::vector<std::pair<int, double>>& out) {
  out.clear();
  for (SparseMatrixR::InnerIterator it(ops.G, v); it; ++it) out.emplace_back(static_cast<int>(it.col()), it.value());
  if (ops.viscousCount() == 0) return;
  const int np = ops.pressureCount();
  const auto& rows = ops.faceViscousRows[v];
  for (int b = 0; b < d; ++b) {
    if (rows[2 * b] >= 0) out.emplace_back(np + rows[2 * b], ops.viscousRows[rows[2 * b]].c1);          // v is u1
    if (rows[2 * b + 1] >= 0) out.emplace_back(np + rows[2 * b + 1], ops.viscousRows[rows[2 * b + 1]].c0);  // v is u0
  }
}

// The band: pressures of the cells beside each cut face and the viscous rows through it, minus
// any closed region that would lie entirely inside it.
template <int d>
std::vector<int> cutFaceBand(const FluidOperators<d>& ops) {
  const int np = ops.pressureCount(), n = np + ops.viscousCount();
  std::vector<char> in(n, 0);
  std::vector<std::pair<int, double>> column;
  for (int v = 0; v < ops.velocityCount(); ++v) {
    if (!(ops.openFraction[v] < 1.0)) continue;
    faceColumn(ops, v, column);
    for (const auto& [unknown, coefficient] : column) in[unknown] = 1;
  }
  if (ops.dofs.closedComponentCount > 0) {
    std::vector<int> outside(ops.dofs.closedComponentCount, 0);
    for (int p = 0; p < np; ++p)
      if (ops.dofs.closedComponent[p] >= 0 && !in[p]) ++outside[ops.dofs.closedComponent[p]];
    for (int p = 0; p < np; ++p)
      if (ops.dofs.closedComponent[p] >= 0 && outside[ops.dofs.closedComponent[p]] == 0) in[p] = 0;
  }
  std::vector<int> band;
  for (int i = 0; i < n; ++i)
    if (in[i]) band.push_back(i);
  return band;
}

}  // namespace

template <int d>
CoupledPreconditioner<d>::CoupledPreconditioner(const FluidOperators<d>& ops, const PoissonPreconditioner<d>& pressure,
                                                CoupledPreconditionerKind kind)
    : ops_(&ops), pressure_(&pressure) {
  const int np = ops.pressureCount(), nr = ops.viscousCount(), n = np + nr;
  viscousInverse_ = CoupledOperator<d>(ops).viscousDiagonal().cwiseInverse();
  rp_.resize(np);
  zp_.resize(np);
  if (kind != CoupledPreconditionerKind::CutCorrected || !ops.cut) return;
  band_ = cutFaceBand(ops);
  if (band_.empty()) return;
  const int m = static_cast<int>(band_.size());
  std::vector<int> local(n, -1);
  for (int k = 0; k < m; ++k) local[band_[k]] = k;

  // Velocity unknowns whose column touches the band: only they contribute to its rows of A.
  std::vector<char> touches(ops.velocityCount(), 0);
  for (int i : band_) {
    if (i < np) {
      for (int v : ops.divergenceFaces[i])
        if (v >= 0) touches[v] = 1;
    } else {
      const ViscousRow& row = ops.viscousRows[i - np];
      if (row.u0 >= 0) touches[row.u0] = 1;
      if (row.u1 >= 0) touches[row.u1] = 1;
    }
  }
  std::vector<Eigen::Triplet<double>> rows;
  std::vector<std::pair<int, double>> column;
  for (int v = 0; v < ops.velocityCount(); ++v) {
    if (!touches[v]) continue;
    faceColumn(ops, v, column);
    const double betaInv = ops.faceBetaInv[v];
    for (const auto& [a, ca] : column) {
      if (local[a] < 0) continue;
      for (const auto& [b, cb] : column) rows.emplace_back(local[a], b, betaInv * ca * cb);
    }
  }
  for (int k = 0; k < m; ++k)
    if (band_[k] >= np) rows.emplace_back(k, band_[k], 1.0);  // the viscous block's identity
  bandRows_.resize(m, n);
  bandRows_.setFromTriplets(rows.begin(), rows.end());

  std::vector<Eigen::Triplet<double>> block;
  for (int k = 0; k < m; ++k)
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(bandRows_, k); it; ++it)
      if (local[it.col()] >= 0) block.emplace_back(k, local[it.col()], it.value());
  Eigen::SparseMatrix<double> bandMatrix(m, m);
  bandMatrix.setFromTriplets(block.begin(), block.end());
  bandSolve_.compute(bandMatrix);
  if (bandSolve_.info() != Eigen::Success)
    throw std::runtime_error("coupled preconditioner: the cut-face band's block of (5.31) is not positive definite");
  residual_.resize(n);
  local_.resize(m);
  correction_.resize(m);
}

template <int d>
void CoupledPreconditioner<d>::applyBlockDiagonal(const Eigen::VectorXd& r, Eigen::VectorXd& z) const {
  const int np = ops_->pressureCount(), nr = ops_->viscousCount();
  rp_ = r.head(np);
  pressure_->apply(rp_, zp_);
  z.head(np) = zp_;
  if (nr > 0) z.tail(nr) = r.tail(nr).cwiseProduct(viscousInverse_);
}

template <int d>
void CoupledPreconditioner<d>::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const {
  if (band_.empty()) {
    applyBlockDiagonal(r, z);
    return;
  }
  const int m = static_cast<int>(band_.size());
  // z1 = L r, supported on the band.
  for (int k = 0; k < m; ++k) local_[k] = r[band_[k]];
  bandZ1_ = bandSolve_.solve(local_);
  const Eigen::VectorXd& z1 = bandZ1_;
  // z2 = B^-1 (r - A z1); A z1 = bandRows_^T z1 (A symmetric).
  residual_ = r;
  for (int k = 0; k < m; ++k)
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(bandRows_, k); it; ++it)
      residual_[it.col()] -= it.value() * z1[k];
  applyBlockDiagonal(residual_, z);
  // z = z1 + z2 - L A z2, with (A z2)_band = bandRows_ z2.
  correction_ = bandRows_ * z;
  local_ = bandSolve_.solve(correction_);
  for (int k = 0; k < m; ++k) z[band_[k]] += z1[k] - local_[k];
}

template <int d>
LinearOperator CoupledPreconditioner<d>::asOperator() const {
  const CoupledPreconditioner* self = this;
  return [self](const Eigen::VectorXd& in, Eigen::VectorXd& out) { self->apply(in, out); };
}

template class CoupledPreconditioner<2>;
template class CoupledPreconditioner<3>;

}  // namespace monolith::solvers

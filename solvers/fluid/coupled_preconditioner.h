#pragma once
// Preconditioners for the coupled pressure-viscosity system (5.31), A = K beta^-1 K^T + diag(0, I)
// on z = (p_hat, u_hat) (spd_systems.h).
//
//  * BlockDiagonal: the Poisson preconditioner on the pressure block, Jacobi on the viscous block
//    (notes 4.4: the thesis code's choice). It leaves out the coupling blocks G^T b G_mu^T.
//  * CutCorrected: the same block-diagonal B, corrected by an exact solve on a thin band of
//    unknowns around the cut faces (the pressures of the cells beside a cut face and the viscous
//    rows that touch one). A cut face has mass theta rho V, so its beta^-1 is large, and through it
//    the pressure and viscous unknowns of the band are almost dependent: the block-diagonal
//    preconditioner misses exactly that, and the coupled CG's iterations grew with resolution
//    (docs/benchmarks.md, "Where the coupled solve's iterations go").
//
// CutCorrected is the symmetric two-step (hybrid Schwarz) combination of the band solve
// L = R^T A_SS^-1 R and B:
//     M^-1 = L + (I - L A) B^-1 (I - A L),
// applied as z1 = L r, z2 = B^-1 (r - A z1), z = z1 + z2 - L A z2. It is symmetric; it is positive
// definite because L and B^-1 are (a vector x with L x = 0 and (I - A L) x = 0 is x = 0), so CG
// keeps its guarantees. A z1 and (A z2)_S need only the band's columns of A, which are stored,
// so one application costs one B^-1, two sparse triangular solves of the band's size and two
// products with the band's columns.
//
// The band's matrix A_SS is a principal submatrix of A and factorised once (sparse LDL^T). A
// closed (pure-Neumann) region that lies entirely inside the band would make it singular; its
// cells are left out of the band. Without cut faces the band is empty and CutCorrected is
// BlockDiagonal, bitwise.
#include "solvers/fluid/krylov.h"
#include "solvers/fluid/operators.h"
#include "solvers/fluid/poisson_preconditioner.h"

#include <Eigen/SparseCholesky>

#include <string>
#include <vector>

namespace monolith::solvers {

enum class CoupledPreconditionerKind { BlockDiagonal, CutCorrected };

std::string toString(CoupledPreconditionerKind kind);

template <int d>
class CoupledPreconditioner {
 public:
  // Keeps references to `ops` and `pressure`, which must outlive it.
  CoupledPreconditioner(const FluidOperators<d>& ops, const PoissonPreconditioner<d>& pressure,
                        CoupledPreconditionerKind kind);
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const;
  LinearOperator asOperator() const;
  // Unknowns of the band (0 for BlockDiagonal or without cut faces).
  int bandSize() const { return static_cast<int>(band_.size()); }
  // The band (indices into z, ascending) and A's rows for it, built from the face stencils (for
  // tests: they must equal the rows of assembleCoupled).
  const std::vector<int>& band() const { return band_; }
  const Eigen::SparseMatrix<double, Eigen::RowMajor>& bandRows() const { return bandRows_; }

 private:
  void applyBlockDiagonal(const Eigen::VectorXd& r, Eigen::VectorXd& z) const;

  const FluidOperators<d>* ops_;
  const PoissonPreconditioner<d>* pressure_;
  Eigen::VectorXd viscousInverse_;
  std::vector<int> band_;  // indices into z, ascending
  // Rows of A for the band's unknowns (= its columns, A being symmetric): |band| x size.
  Eigen::SparseMatrix<double, Eigen::RowMajor> bandRows_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> bandSolve_;
  // Workspace (one instance must not be applied from two threads at once).
  mutable Eigen::VectorXd rp_, zp_, residual_, local_, bandZ1_, correction_;
};

}  // namespace monolith::solvers

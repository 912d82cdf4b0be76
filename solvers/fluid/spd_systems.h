#pragma once
// The SPD systems of the fluid step, applied matrix-free (thesis Sec. 5.2, 5.7, 6.2.6; notes 4.4):
//
//  * PoissonOperator:  G^T beta^-1 G            (pressure projection, unknown p_hat = dt p)
//  * CoupledOperator:  A = K beta^-1 K^T + diag(0, I) with K = [G^T; G_mu], i.e. eq. (5.31)
//                      [[G^T b G, G^T b G_mu^T], [G_mu b G, I + G_mu b G_mu^T]], b = beta^-1,
//                      on z = (p_hat, u_hat) stacked as [pressure unknowns, viscous rows]
//  * ViscousOperator:  Theta + beta_1^-1 G_mu^T G_mu  (= I + dt nu L per component: the implicit
//                      viscosity step of the Chorin splitting, divided through by the mass
//                      beta_1 = rho V_cell of a whole face; Theta = diag(open fractions) is I
//                      without cut faces and keeps the system symmetric with them)
//
// With cut faces (operators.h) beta^-1 is per face; the Poisson stencil then weights each free
// face by its open fraction.
//
// Each apply is a sequence of row-parallel stencil loops (deterministic). The objects keep a
// workspace, so one instance must not be applied from two threads at once.
#include "solvers/fluid/krylov.h"
#include "solvers/fluid/operators.h"

namespace monolith::solvers {

template <int d>
class PoissonOperator {
 public:
  explicit PoissonOperator(const FluidOperators<d>& ops);
  void apply(const Eigen::VectorXd& p, Eigen::VectorXd& out) const;
  Eigen::VectorXd diagonal() const;
  LinearOperator asOperator() const;

 private:
  const FluidOperators<d>* ops_;
  // Cell-to-cell stencil precomputed from the face tables (one indirection less per entry: the
  // apply is the bandwidth-bound core of every CG iteration): neighbouring pressure unknown across
  // each free face (-1: Dirichlet p = 0 or no free face) and the number of free faces.
  std::vector<std::array<int, 2 * d>> neighbours_;
  std::vector<int> freeFaces_;
  std::vector<std::array<double, 2 * d>> weights_;  // cut faces only: open fraction per face, 0 if none
};

template <int d>
class CoupledOperator {
 public:
  explicit CoupledOperator(const FluidOperators<d>& ops);
  int size() const { return ops_->pressureCount() + ops_->viscousCount(); }
  void apply(const Eigen::VectorXd& z, Eigen::VectorXd& out) const;
  // Diagonal of the viscous block I + G_mu b G_mu^T (for the block preconditioner).
  Eigen::VectorXd viscousDiagonal() const;
  LinearOperator asOperator() const;

 private:
  const FluidOperators<d>* ops_;
  mutable Eigen::VectorXd faces_;  // G p_hat + G_mu^T u_hat, then times beta^-1
};

template <int d>
class ViscousOperator {
 public:
  explicit ViscousOperator(const FluidOperators<d>& ops);
  void apply(const Eigen::VectorXd& u, Eigen::VectorXd& out) const;
  Eigen::VectorXd diagonal() const;
  LinearOperator asOperator() const;

 private:
  const FluidOperators<d>* ops_;
  mutable Eigen::VectorXd rows_;
};

// Orthogonal projector removing, from the pressure entries [offset, offset + np) of a vector, the
// mean over every closed (pure-Neumann) region: the null space of G and of (5.31) (Sec. 6.2.6).
// Empty when there is no closed region.
Projector closedRegionProjector(const FluidDofs& dofs, int offset = 0);

}  // namespace monolith::solvers

#pragma once
// The monolithic fluid-structure solve, thesis eq. (5.30) in the form of Sec. 5.8:
//
//     (K B^-1 K^T + P) z = K w,    w^{n+1} = w - B^-1 K^T z,
//
// with w = (u*, v*), B = diag(beta, M), z = (p_hat, u_hat, lambda, v_hat) and
//     K = [[G^T, 0], [G_mu, 0], [-W, W J], [0, C]],   P = diag(0, I, 0, I)
// (C: the structure's factored damping, C^T C = -dt D, Sec. 5.5.1; rigid bodies have none, and
// then v_hat is empty). Written out:
//     u^{n+1} = u* - beta^-1 (G p_hat + G_mu^T u_hat - W^T lambda)      (eq. 5.8 with viscosity)
//     v^{n+1} = v* - M^-1 (J^T W^T lambda + C^T v_hat)                    (eq. 5.11 with damping)
// and the rows of the system are G^T u^{n+1} = g (incompressibility), u_hat = G_mu u^{n+1} + h
// (viscous stresses), W u^{n+1} = W J v^{n+1} (the coupling constraint, eq. 5.12) and
// v_hat = C v^{n+1} (backward-Euler damping: M v^{n+1} = M v* + dt D v^{n+1} - ...). With W = 0
// it is the fluid's (5.31) (spd_systems.h). The right-hand side carries the known boundary terms
// (g, h) as (5.31) does.
//
// Energy (Sec. 5.8): with g = 0 and h = 0 (walls at rest),
//     2 KE^{n+1} - 2 KE* = -z^T (K B^-1 K^T + 2P) z <= 0,  KE = 1/2 u^T beta u + 1/2 v^T M v,
// so the solve never adds kinetic energy; fsiProjection reports both energies.
//
// Preconditioners (FsiPreconditionerKind):
//  * None: plain CG;
//  Every variant below is the identity on the damping block I + C M^-1 C^T (v_hat).
//  * BlockJacobi: the fluid's block preconditioner (coupled_preconditioner.h) on (p_hat, u_hat)
//    and the diagonal of W (beta^-1 + J M^-1 J^T) W^T on lambda;
//  * BlockExact: the same fluid blocks and the exact inverse of the lambda block,
//      (b I + J M^-1 J^T)^-1 = b^-1 I - b^-2 J (M + b^-1 J^T J)^-1 J^T   (Woodbury, b = beta^-1),
//    a factorisation of the structure-sized matrix M + b^-1 J^T J (3 or 6 per rigid body).
//    The lambda block is dense within each body (J M^-1 J^T couples all of its faces), which is
//    what the Jacobi variant misses.
//  * Schur: lambda eliminated exactly, the rest approximated. With F = (p_hat, u_hat),
//      A = [[A_FF, A_Fl], [A_lF, C]],  C = W (beta^-1 + J M^-1 J^T) W^T,
//    the symmetric block factorisation
//      P^-1 = [[I, 0], [-C^-1 A_lF, I]] diag(S~^-1, C^-1) [[I, -A_Fl C^-1], [0, I]]
//    with S~ approximating the Schur complement A_FF - A_Fl C^-1 A_lF. On the pressure block that
//    Schur complement is the Poisson matrix of the same fluid with the coupling faces closed
//    (the fluid cannot flow into a rigid body; the one-way obstacle's matrix) plus a term of rank
//    3 (6) per body, its rigid motions: S~^-1 is the Poisson preconditioner of that closed
//    domain (built once per solve), and CG takes care of the low-rank rest. On the viscous block
//    likewise the rows' ends on coupling faces drop out; that block gets its Jacobi. What remains
//    neglected is the pressure-viscous coupling G^T b G_mu^T, as in the fluid's own (5.31)
//    preconditioner: iterations grow with the viscous number dt nu / dx^2 only.
//    P^-1 is SPD whenever S~^-1 is.
//    The block variants neglect exactly the pressure-lambda coupling that this one keeps, and it
//    is what their iteration counts grow with (docs/benchmarks_fsi.md).
#include "solvers/fluid/coupled_preconditioner.h"
#include "solvers/fluid/krylov.h"
#include "solvers/fluid/operators.h"
#include "solvers/fluid/poisson_preconditioner.h"
#include "solvers/fluid/structure_coupling.h"

#include <Eigen/SparseCholesky>

#include <memory>
#include <string>

namespace monolith::solvers {

enum class FsiPreconditionerKind { None, BlockJacobi, BlockExact, Schur };
std::string toString(FsiPreconditionerKind kind);

template <int d>
class FsiOperator {
 public:
  // Keeps references; both must outlive it. The coupling faces must be free velocity unknowns
  // without cut (staircase faces).
  FsiOperator(const FluidOperators<d>& ops, const StructureCoupling& coupling);
  int size() const { return np_ + nr_ + nc_ + nd_; }
  void apply(const Eigen::VectorXd& z, Eigen::VectorXd& out) const;
  // B^-1 K^T z: the fluid part (per velocity unknown) and the structure part.
  void velocityChange(const Eigen::VectorXd& z, Eigen::VectorXd& fluid, Eigen::VectorXd& structure) const;
  // K w plus the known boundary terms.
  Eigen::VectorXd rightHandSide(const Eigen::VectorXd& uStar, const Eigen::VectorXd& vStar) const;
  // Diagonal of the lambda block W (beta^-1 + J M^-1 J^T) W^T.
  Eigen::VectorXd constraintDiagonal() const;
  LinearOperator asOperator() const;

 private:
  const FluidOperators<d>* ops_;
  const StructureCoupling* coupling_;
  int np_, nr_, nc_, nd_;
  SparseMatrixR JT_;  // J^T
  mutable Eigen::VectorXd faces_, structure_;
};

template <int d>
class FsiPreconditioner {
 public:
  // `fluid` may be null for None.
  // `pressureKind`: the Poisson preconditioner of the closed domain (Schur only).
  FsiPreconditioner(const FsiOperator<d>& system, const FluidOperators<d>& ops, const StructureCoupling& coupling,
                    const CoupledPreconditioner<d>* fluid, FsiPreconditionerKind kind,
                    PoissonPreconditionerKind pressureKind = PoissonPreconditionerKind::MIC0);
  ~FsiPreconditioner();
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const;
  LinearOperator asOperator() const;

 private:
  void applyConstraintInverse(const Eigen::VectorXd& r, Eigen::VectorXd& z) const;  // C^-1 (Woodbury)
  FsiPreconditionerKind kind_;
  const FluidOperators<d>* ops_;
  const StructureCoupling* coupling_;
  const CoupledPreconditioner<d>* fluid_;
  std::unique_ptr<FluidOperators<d>> closed_;              // Schur: coupling faces closed
  std::unique_ptr<PoissonPreconditioner<d>> closedPoisson_;
  Eigen::VectorXd viscousInverse_;  // Schur: Jacobi of the closed domain's viscous block
  int nf_ = 0, nc_ = 0;
  double b_ = 0;  // beta^-1 on a (whole) coupling face
  Eigen::VectorXd constraintInverse_;
  SparseMatrixR J_, JT_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> schur_;  // M + b^-1 J^T J
  mutable Eigen::VectorXd rf_, zf_;
};

struct FsiReport {
  CgReport solve;
  Eigen::VectorXd pressure;     // p = p_hat / dt per cell
  Eigen::VectorXd lambda;       // coupling impulses
  Eigen::VectorXd structureImpulse;  // J^T W^T lambda: minus the fluid's impulse on the structure dofs
  double dampingWork = 0;            // |v_hat|^2 = -dt v^T D v: energy the damping took (>= 0)
  double kineticEnergyBefore = 0;    // 1/2 u*^T beta u* + 1/2 v*^T M v* (velocity unknowns only)
  double kineticEnergyAfter = 0;
};

// Solves (5.30) and updates the face velocities (free and prescribed faces, as the fluid
// projection does) and coupling.velocity (v* in, v^{n+1} out).
template <int d>
FsiReport fsiProjection(const FluidOperators<d>& ops, StructureCoupling& coupling, Eigen::VectorXd& faceVelocities,
                        const CgSettings& settings, const CoupledPreconditioner<d>* fluidPreconditioner,
                        FsiPreconditionerKind kind,
                        PoissonPreconditionerKind pressureKind = PoissonPreconditionerKind::MIC0);

// Assembled K B^-1 K^T + P (tests, inspection).
template <int d>
Eigen::MatrixXd assembleFsiDense(const FluidOperators<d>& ops, const StructureCoupling& coupling);

}  // namespace monolith::solvers

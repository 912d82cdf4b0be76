#pragma once
// The fluid projection step in its two forms (thesis Sec. 5.2, 5.7):
//
// (a) Chorin splitting [37]: implicit viscosity, then pressure projection.
//       (I + beta^-1 G_mu^T G_mu) u** = u* - beta^-1 G_mu^T h          (= (I + dt nu L) per component)
//       G^T beta^-1 G p_hat = G^T u** - g,   u = u** - beta^-1 G p_hat      (eq. 5.4)
// (b) Coupled SPD pressure-viscosity solve, eq. (5.31) with known boundary values:
//       [[G^T b G, G^T b G_mu^T], [G_mu b G, I + G_mu b G_mu^T]] (p_hat, u_hat)
//           = (G^T u* - g, G_mu u* + h),   b = beta^-1,
//       u = u* - beta^-1 (G p_hat + G_mu^T u_hat).
//     Derivation (eq. 5.27 with W = 0): beta u = beta u* - G p_hat - G_mu^T u_hat with
//     u_hat = G_mu u + h (the viscous row values at n+1, known ends included); multiplying by
//     G^T beta^-1 and using the constraint G^T u = g (i.e. D u = 0) gives the first row, multiplying
//     by G_mu beta^-1 and adding h gives the second. The notes (4.4) leave the sign of the fluid
//     update unresolved; the unit tests fix it (u = u* - beta^-1 K^T z: divergence free, equal to
//     (a) when mu = 0, and exactly the backward-Euler Stokes step).
//
// Here g = prescribed-face fluxes (operators.h), h = known parts of the viscous rows, p_hat = dt p.
// Velocities are full face vectors (one value per face of the layout): on input the free faces
// hold u*, on output free and prescribed faces hold u^{n+1}; inactive faces are left unchanged.
//
// Pure-Neumann pressure (a fluid region with no Dirichlet contact, e.g. a closed box): the
// constant on the region is in the null space of G and of (5.31) (Sec. 6.2.6). The right-hand side
// is projected to zero mean on each such region (this only removes rounding when the prescribed
// fluxes are compatible, and gives the least-squares answer when they are not), and CG projects
// every preconditioned residual (krylov.h), so the returned pressure has zero mean on the region.
#include "solvers/fluid/coupled_preconditioner.h"
#include "solvers/fluid/krylov.h"
#include "solvers/fluid/operators.h"
#include "solvers/fluid/poisson_preconditioner.h"

namespace monolith::solvers {

struct ProjectionSettings {
  PoissonPreconditionerKind preconditioner = PoissonPreconditionerKind::MIC0;
  CoupledPreconditionerKind coupledPreconditioner = CoupledPreconditionerKind::CutCorrected;  // (b) only
  CgSettings solve{10000, 1e-10, 0};     // pressure Poisson or the coupled (5.31) solve
  CgSettings viscosity{10000, 1e-10, 0}; // Chorin's implicit viscosity solve (Jacobi-PCG)
};

struct ProjectionReport {
  CgReport viscosity;        // (a) only; zero iterations when mu = 0
  CgReport solve;            // the pressure (a) or coupled (b) solve
  Eigen::VectorXd pressureImpulse;  // p_hat per pressure unknown (warm starts, diagnostics)
  Eigen::VectorXd pressure;  // p = p_hat / dt per cell; 0 on non-fluid cells
};

// (a), first half. Jacobi-preconditioned CG; the initial guess is u*. No-op when mu = 0.
template <int d>
CgReport implicitViscosity(const FluidOperators<d>& ops, Eigen::VectorXd& faceVelocities, const CgSettings& settings);

// (a), second half (or the whole projection when mu = 0). `preconditioner` may be null: one of
// settings.preconditioner is then built for this call.
template <int d>
ProjectionReport pressureProjection(const FluidOperators<d>& ops, Eigen::VectorXd& faceVelocities,
                                    const ProjectionSettings& settings,
                                    const PoissonPreconditioner<d>* preconditioner = nullptr);

// (a) complete.
template <int d>
ProjectionReport chorinProjection(const FluidOperators<d>& ops, Eigen::VectorXd& faceVelocities,
                                  const ProjectionSettings& settings,
                                  const PoissonPreconditioner<d>* preconditioner = nullptr);

// (b). Block preconditioner: `preconditioner` (settings.preconditioner, MIC(0) by default) on the
// pressure block, Jacobi on the viscous block (notes 4.4: IC(0) on the pressure block and a
// diagonal on the others), with cut faces corrected by an exact solve on the band around them
// (settings.coupledPreconditioner, coupled_preconditioner.h). `coupled` may be null: one is then
// built for this call around `preconditioner`.
template <int d>
ProjectionReport coupledProjection(const FluidOperators<d>& ops, Eigen::VectorXd& faceVelocities,
                                   const ProjectionSettings& settings,
                                   const PoissonPreconditioner<d>* preconditioner = nullptr,
                                   const CoupledPreconditioner<d>* coupled = nullptr);

}  // namespace monolith::solvers

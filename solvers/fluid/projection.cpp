// Chorin splitting and the coupled SPD pressure-viscosity solve (see projection.h).
#include "solvers/fluid/projection.h"

#include "solvers/fluid/parallel.h"
#include "solvers/fluid/spd_systems.h"

#include <memory>

namespace monolith::solvers {

namespace {

template <int d>
Eigen::VectorXd pressurePerCell(const FluidOperators<d>& ops, const Eigen::VectorXd& pHat) {
  Eigen::VectorXd p = Eigen::VectorXd::Zero(ops.domain.layout.cellCount());
  for (int i = 0; i < ops.pressureCount(); ++i) p[ops.dofs.pressureToCell[i]] = pHat[i] / ops.params.dt;
  return p;
}

// Uses the caller's preconditioner or builds the requested one.
template <int d>
const PoissonPreconditioner<d>* choosePreconditioner(const FluidOperators<d>& ops, const ProjectionSettings& settings,
                                                     const PoissonPreconditioner<d>* given,
                                                     std::unique_ptr<PoissonPreconditioner<d>>& owned) {
  if (given) return given;
  owned = std::make_unique<PoissonPreconditioner<d>>(ops, settings.preconditioner);
  return owned.get();
}

}  // namespace

template <int d>
CgReport implicitViscosity(const FluidOperators<d>& ops, Eigen::VectorXd& faceVelocities, const CgSettings& settings) {
  if (ops.viscousCount() == 0) return {};
  const Eigen::VectorXd uStar = freeVelocities(ops, faceVelocities);
  // rhs = Theta u* - beta_1^-1 G_mu^T h: the known ends of the viscous rows (walls, obstacles,
  // inflow); Theta = I without cut faces (spd_systems.h).
  Eigen::VectorXd rhs(ops.velocityCount());
  applyViscousGradientTranspose(ops, ops.viscousKnown, rhs);
  rhs = ops.openFraction.cwiseProduct(uStar) - ops.betaInv * rhs;
  ViscousOperator<d> system(ops);
  Eigen::VectorXd u = uStar;
  const CgReport report =
      conjugateGradient(system.asOperator(), jacobiPreconditioner(system.diagonal()), {}, rhs, u, settings);
  writeVelocities(ops, u, faceVelocities);
  return report;
}

template <int d>
ProjectionReport pressureProjection(const FluidOperators<d>& ops, Eigen::VectorXd& faceVelocities,
                                    const ProjectionSettings& settings, const PoissonPreconditioner<d>* given) {
  std::unique_ptr<PoissonPreconditioner<d>> owned;
  const PoissonPreconditioner<d>* pre = choosePreconditioner(ops, settings, given, owned);
  Eigen::VectorXd u = freeVelocities(ops, faceVelocities);
  Eigen::VectorXd rhs(ops.pressureCount());
  applyGradientTranspose(ops, u, rhs);
  rhs -= ops.prescribedDivergence;
  PoissonOperator<d> system(ops);
  ProjectionReport report;
  report.pressureImpulse.setZero(ops.pressureCount());
  report.solve = conjugateGradient(system.asOperator(), pre->asOperator(), closedRegionProjector(ops.dofs), rhs,
                                   report.pressureImpulse, settings.solve);
  Eigen::VectorXd grad(ops.velocityCount());
  applyGradient(ops, report.pressureImpulse, grad);
  if (ops.cut) u -= faceBetaInverse(ops).cwiseProduct(grad);
  else u -= ops.betaInv * grad;
  writeVelocities(ops, u, faceVelocities);
  report.pressure = pressurePerCell(ops, report.pressureImpulse);
  return report;
}

template <int d>
ProjectionReport chorinProjection(const FluidOperators<d>& ops, Eigen::VectorXd& faceVelocities,
                                  const ProjectionSettings& settings, const PoissonPreconditioner<d>* given) {
  const CgReport viscosity = implicitViscosity(ops, faceVelocities, settings.viscosity);
  ProjectionReport report = pressureProjection(ops, faceVelocities, settings, given);
  report.viscosity = viscosity;
  return report;
}

template <int d>
ProjectionReport coupledProjection(const FluidOperators<d>& ops, Eigen::VectorXd& faceVelocities,
                                   const ProjectionSettings& settings, const PoissonPreconditioner<d>* given,
                                   const CoupledPreconditioner<d>* coupled) {
  std::unique_ptr<PoissonPreconditioner<d>> owned;
  std::unique_ptr<CoupledPreconditioner<d>> ownedCoupled;
  if (!coupled) {
    const PoissonPreconditioner<d>* pre = choosePreconditioner(ops, settings, given, owned);
    ownedCoupled = std::make_unique<CoupledPreconditioner<d>>(ops, *pre, settings.coupledPreconditioner);
    coupled = ownedCoupled.get();
  }
  const int np = ops.pressureCount(), nr = ops.viscousCount();
  const Eigen::VectorXd uStar = freeVelocities(ops, faceVelocities);

  // rhs = K u* + known terms = (G^T u* - g, G_mu u* + h).
  Eigen::VectorXd rhs(np + nr);
  applyGradientTranspose(ops, uStar, rhs.head(np));
  rhs.head(np) -= ops.prescribedDivergence;
  if (nr > 0) {
    applyViscousGradient(ops, uStar, rhs.tail(nr));
    rhs.tail(nr) += ops.viscousKnown;
  }

  CoupledOperator<d> system(ops);
  ProjectionReport report;
  Eigen::VectorXd z = Eigen::VectorXd::Zero(np + nr);
  report.solve = conjugateGradient(system.asOperator(), coupled->asOperator(), closedRegionProjector(ops.dofs, 0), rhs,
                                   z, settings.solve);

  // u = u* - beta^-1 (G p_hat + G_mu^T u_hat)
  Eigen::VectorXd faces(ops.velocityCount()), visc(ops.velocityCount());
  applyGradient(ops, z.head(np), faces);
  if (nr > 0) {
    applyViscousGradientTranspose(ops, z.tail(nr), visc);
    faces += visc;
  }
  const Eigen::VectorXd u = ops.cut ? Eigen::VectorXd(uStar - faceBetaInverse(ops).cwiseProduct(faces))
                                    : Eigen::VectorXd(uStar - ops.betaInv * faces);
  writeVelocities(ops, u, faceVelocities);
  report.pressureImpulse = z.head(np);
  report.pressure = pressurePerCell(ops, report.pressureImpulse);
  return report;
}

#define MONOLITH_FLUID_PROJECTION(D)                                                                        \
  template CgReport implicitViscosity<D>(const FluidOperators<D>&, Eigen::VectorXd&, const CgSettings&);    \
  template ProjectionReport pressureProjection<D>(const FluidOperators<D>&, Eigen::VectorXd&,               \
                                                  const ProjectionSettings&, const PoissonPreconditioner<D>*); \
  template ProjectionReport chorinProjection<D>(const FluidOperators<D>&, Eigen::VectorXd&,                 \
                                                const ProjectionSettings&, const PoissonPreconditioner<D>*);   \
  template ProjectionReport coupledProjection<D>(const FluidOperators<D>&, Eigen::VectorXd&,                \
                                                 const ProjectionSettings&, const PoissonPreconditioner<D>*, \
                                                 const CoupledPreconditioner<D>*);

MONOLITH_FLUID_PROJECTION(2)
MONOLITH_FLUID_PROJECTION(3)
#undef MONOLITH_FLUID_PROJECTION

}  // namespace monolith::solvers

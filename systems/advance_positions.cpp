#include "systems/advance_positions.h"

#include <algorithm>
#include <cmath>

#include "solvers/rigid_rotation.h"
#include "solvers/rigid_rotation_settings.h"
#include "systems/parallel.h"
#include "systems/rigid_inertia.h"

namespace monolith {

template <int d>
void AdvanceRigidPositions<d>::run(World<d>& world, StepContext& ctx) {
  auto& forces = world.template pool<RigidForces<d>>();  // one per dynamic body
  auto& bodies = world.template pool<RigidBody<d>>();
  const double dt = ctx.dt;
  const RigidRotationSettings rule = world.template resource<RigidRotationSettings>();
  reports_.assign(forces.size(), BodyReport{});

  const auto* sleeps = world.template findPool<Sleep<d>>();
  parallelForEachIndex(forces.size(), [&](std::size_t i) {
    RigidBody<d>* body = bodies.get(forces.entities()[i]);
    if (!body || body->isStatic || isAsleep<d>(sleeps, forces.entities()[i])) return;
    body->x += dt * body->v;
    if constexpr (d == 2) {
      body->orientation += dt * body->omega()(0);
    } else {
      const solvers::BodyInertia inertia = bodyInertia(*body);
      const double energyBefore = solvers::rotationalKineticEnergy(inertia, body->orientation, body->L);
      body->orientation = solvers::advanceOrientation(static_cast<solvers::RotationOrder>(rule.order), dt, inertia,
                                                      body->orientation, body->L);
      BodyReport& report = reports_[i];
      if (rule.energyFix) {
        const auto fix = solvers::correctOrientationForKineticEnergy(body->orientation, inertia, body->L, energyBefore);
        report.fallbackRotations = fix.fallbackRotations;
        report.residualAccepted = fix.status == solvers::EnergyFixReport::Status::ResidualAccepted;
      }
      const double energyAfter = solvers::rotationalKineticEnergy(inertia, body->orientation, body->L);
      if (energyBefore > 0) report.relativeEnergyChange = std::abs(energyAfter - energyBefore) / energyBefore;
    }
  });

  if constexpr (d == 3) {
    // Serial reduction in pool order: deterministic for any thread count.
    double worst = 0;
    int fallbacks = 0, residuals = 0;
    for (const auto& r : reports_) {
      worst = std::max(worst, r.relativeEnergyChange);
      fallbacks += r.fallbackRotations;
      residuals += r.residualAccepted ? 1 : 0;
    }
    ctx.diagnostics.set("rotation_max_relative_energy_change", worst);
    ctx.diagnostics.set("energy_fix_fallback_rotations", fallbacks);
    ctx.diagnostics.set("energy_fix_residuals_accepted", residuals);
  }
}

template class AdvanceRigidPositions<2>;
template class AdvanceRigidPositions<3>;

}  // namespace monolith

#include "systems/advance_velocity.h"

#include "systems/parallel.h"

namespace monolith {

template <int d>
void RigidHalfKick<d>::run(World<d>& world, StepContext& ctx) {
  auto& forces = world.template pool<RigidForces<d>>();
  auto& bodies = world.template pool<RigidBody<d>>();
  const auto* sleeps = world.template findPool<Sleep<d>>();
  const double halfDt = 0.5 * ctx.dt;
  parallelForEachIndex(forces.size(), [&](std::size_t i) {
    RigidBody<d>* body = bodies.get(forces.entities()[i]);
    // A sleeping body is held still (systems/sleep.h); one woken in Step II gets this kick then.
    if (!body || body->isStatic || isAsleep<d>(sleeps, forces.entities()[i])) return;
    const RigidForces<d>& f = forces.components()[i];
    body->v += (halfDt / body->mass) * f.force;
    body->L += halfDt * f.torque;
  });
}

template class RigidHalfKick<2>;
template class RigidHalfKick<3>;

}  // namespace monolith

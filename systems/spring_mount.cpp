// Spring-mounted rigid bodies: f = -k (x - anchor) - c v (see spring_mount.h).
#include "systems/spring_mount.h"

namespace monolith {

template <int d>
void SpringMountForces<d>::run(World<d>& world, StepContext&) {
  auto& mounts = world.template pool<SpringMount<d>>();
  // Serial in pool order: a handful of mounted bodies.
  for (std::size_t i = 0; i < mounts.size(); ++i) {
    const Entity e = mounts.entities()[i];
    const RigidBody<d>* body = world.template get<RigidBody<d>>(e);
    RigidForces<d>* f = world.template get<RigidForces<d>>(e);
    if (!body || !f) continue;
    const SpringMount<d>& m = mounts.components()[i];
    f->force -= m.stiffness.cwiseProduct(body->x - m.anchor) + m.damping.cwiseProduct(body->v);
  }
}

template class SpringMountForces<2>;
template class SpringMountForces<3>;

}  // namespace monolith

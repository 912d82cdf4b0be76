#include "systems/rigid_forces.h"

#include "systems/parallel.h"

namespace monolith {

template <int d>
void ClearRigidForces<d>::run(World<d>& world, StepContext&) {
  auto& forces = world.template pool<RigidForces<d>>().components();
  parallelForEachIndex(forces.size(), [&](std::size_t i) {
    forces[i].force.setZero();
    forces[i].torque.setZero();
  });
}

template <int d>
void GravityForce<d>::run(World<d>& world, StepContext&) {
  auto& pool = world.template pool<RigidForces<d>>();
  auto& bodies = world.template pool<RigidBody<d>>();
  const Vec<d> g = world.settings().gravity;
  parallelForEachIndex(pool.size(), [&](std::size_t i) {
    if (const auto* body = bodies.get(pool.entities()[i])) pool.components()[i].force += body->mass * g;
  });
}

template <int d>
void ExternalForces<d>::run(World<d>& world, StepContext&) {
  auto& external = world.template pool<ExternalForce<d>>();
  auto& forces = world.template pool<RigidForces<d>>();
  // Serial: a handful of bodies carry external forces; order fixed by the pool.
  for (std::size_t i = 0; i < external.size(); ++i) {
    if (auto* f = forces.get(external.entities()[i])) {
      f->force += external.components()[i].force;
      f->torque += external.components()[i].torque;
    }
  }
}

template class ClearRigidForces<2>;
template class ClearRigidForces<3>;
template class GravityForce<2>;
template class GravityForce<3>;
template class ExternalForces<2>;
template class ExternalForces<3>;

}  // namespace monolith

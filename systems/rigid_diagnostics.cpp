#include "systems/rigid_diagnostics.h"

namespace monolith {

template <int d>
RigidTotals measureRigidTotals(const World<d>& world) {
  RigidTotals t;
  const auto* pool = world.template findPool<RigidBody<d>>();
  if (!pool) return t;
  const Vec<d> g = world.settings().gravity;
  for (const auto& b : pool->components()) {
    if (b.isStatic) continue;
    t.kinetic += b.translationalKineticEnergy() + b.rotationalKineticEnergy();
    t.potential -= b.mass * g.dot(b.x);
    Eigen::Vector3d x = Eigen::Vector3d::Zero(), p = Eigen::Vector3d::Zero(), L = Eigen::Vector3d::Zero();
    x.template head<d>() = b.x;
    p.template head<d>() = b.mass * b.v;
    if constexpr (d == 3) L = b.L;
    else L.z() = b.L(0);
    t.linearMomentum += p;
    t.angularMomentum += x.cross(p) + L;
  }
  return t;
}

template <int d>
void RigidDiagnostics<d>::run(World<d>& world, StepContext& ctx) {
  const RigidTotals t = measureRigidTotals(world);
  auto& out = ctx.diagnostics;  // add, not set: other systems (the fluid) contribute to the same totals
  out.add("kinetic_energy", t.kinetic);
  out.add("potential_energy", t.potential);
  out.add("total_energy", t.kinetic + t.potential);
  out.add("linear_momentum_x", t.linearMomentum.x());
  out.add("linear_momentum_y", t.linearMomentum.y());
  out.add("linear_momentum_z", t.linearMomentum.z());
  out.add("angular_momentum_x", t.angularMomentum.x());
  out.add("angular_momentum_y", t.angularMomentum.y());
  out.add("angular_momentum_z", t.angularMomentum.z());
}

template RigidTotals measureRigidTotals<2>(const World<2>&);
template RigidTotals measureRigidTotals<3>(const World<3>&);
template class RigidDiagnostics<2>;
template class RigidDiagnostics<3>;

}  // namespace monolith

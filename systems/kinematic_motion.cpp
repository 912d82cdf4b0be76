#include "systems/kinematic_motion.h"

namespace monolith {

template <int d>
void ScriptKinematicVelocity<d>::run(World<d>& world, StepContext& ctx) {
  world.template each<KinematicMotion<d>, RigidBody<d>>([&](Entity, KinematicMotion<d>& k, RigidBody<d>& b) {
    AngularVec<d> w;
    k.velocityAt(ctx.time + 0.5 * ctx.dt, b.v, w);
    b.setOmega(w);
  });
}

template <int d>
void AdvanceKinematicPositions<d>::run(World<d>& world, StepContext& ctx) {
  world.template each<KinematicMotion<d>, RigidBody<d>>([&](Entity, KinematicMotion<d>&, RigidBody<d>& b) {
    const AngularVec<d> w = b.omega();
    b.x += ctx.dt * b.v;
    if constexpr (d == 3) {
      const double angle = ctx.dt * w.norm();
      if (angle > 0) b.orientation = (Eigen::Quaterniond(Eigen::AngleAxisd(angle, w.normalized())) * b.orientation).normalized();
    } else {
      b.orientation += ctx.dt * w(0);
    }
  });
}

template class ScriptKinematicVelocity<2>;
template class ScriptKinematicVelocity<3>;
template class AdvanceKinematicPositions<2>;
template class AdvanceKinematicPositions<3>;

}  // namespace monolith

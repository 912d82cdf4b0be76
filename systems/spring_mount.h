#pragma once
// The force of spring_mount components (components/spring_mount.h) on their bodies, at both
// Newmark force evaluations (x^n, v^n and x^{n+1}, v^{n+1/2}): explicit, like every rigid force.
#include "components/spring_mount.h"
#include "systems/rigid_forces.h"

namespace monolith {

template <int d>
class SpringMountForces final : public RigidForceSystem<d> {
 public:
  explicit SpringMountForces(Stage s) : RigidForceSystem<d>("spring_mount_forces", s) {}
  std::vector<std::string> reads() const override { return {SpringMount<d>::kName, RigidBody<d>::kName}; }
  std::vector<std::string> writes() const override { return {RigidForces<d>::kName}; }
  bool needed(const World<d>& w) const override {
    return w.template count<SpringMount<d>>() > 0 && w.template count<RigidForces<d>>() > 0;
  }
  void run(World<d>& world, StepContext& ctx) override;
};

}  // namespace monolith

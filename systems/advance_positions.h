#pragma once
// Step IV, item 1 (Sec. 4.6) for rigid bodies: x^{n+1} = x^n + dt v^{n+1/2}, and the orientation
// advanced with L^{n+1/2} held fixed in world space by the rule chosen in the scene
// (first order [169], second order Sec. 4.4.1, third order App. A), followed by the
// kinetic-energy orientation fix of Sec. 2.2.2-2.2.4: the rotational energy 1/2 L.I^{-1}L must
// not change during a drift with L fixed, so the fix rotates the body about an axis
// perpendicular to L until it matches the energy before the drift (momentum stays exact).
// In 2-D the inertia is a scalar: the angle advances by dt w exactly and energy is conserved
// without any fix.
#include "components/forces.h"
#include "components/rigid_body.h"
#include "components/sleep.h"
#include "ecs/system.h"

namespace monolith {

template <int d>
class AdvanceRigidPositions final : public System<d> {
 public:
  std::string name() const override { return "advance_rigid_positions"; }
  Stage stage() const override { return Stage::AdvancePositions; }
  std::vector<std::string> reads() const override { return {Sleep<d>::kName}; }
  std::vector<std::string> writes() const override { return {RigidBody<d>::kName}; }
  bool needed(const World<d>& w) const override { return w.template count<RigidForces<d>>() > 0; }
  void run(World<d>& world, StepContext& ctx) override;

 private:
  struct BodyReport {
    double relativeEnergyChange = 0;  // |KE_after - KE_before| / KE_before of the drift
    int fallbackRotations = 0;
    bool residualAccepted = false;
  };
  std::vector<BodyReport> reports_;  // reused across steps: no allocation per step
};

}  // namespace monolith

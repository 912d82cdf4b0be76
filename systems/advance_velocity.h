#pragma once
// Step I (Sec. 4.3) and Step V (Sec. 4.7) for rigid bodies: the two explicit half kicks of the
// Newmark/trapezoid scheme,
//   I: v^{n+1/2} = v^n + dt/2 F(x^n)/m,          L^{n+1/2} = L^n + dt/2 tau(x^n)
//   V: v^{n+1}   = v^{n+1/2} + dt/2 F(x^{n+1})/m, L^{n+1}  = L^{n+1/2} + dt/2 tau(x^{n+1})
// With constant forces this reproduces free flight exactly (x^{n+1} = x^n + dt v^n + dt^2/2 a).
#include "components/forces.h"
#include "components/rigid_body.h"
#include "components/sleep.h"
#include "ecs/system.h"

namespace monolith {

template <int d>
class RigidHalfKick : public System<d> {
 public:
  explicit RigidHalfKick(Stage stage) : stage_(stage) {}
  std::string name() const override {
    return stage_ == Stage::AdvanceVelocityHalf ? "advance_rigid_velocity_half" : "advance_rigid_velocity";
  }
  Stage stage() const override { return stage_; }
  std::vector<std::string> reads() const override { return {RigidForces<d>::kName, Sleep<d>::kName}; }
  std::vector<std::string> writes() const override { return {RigidBody<d>::kName}; }
  bool needed(const World<d>& w) const override { return w.template count<RigidForces<d>>() > 0; }
  void run(World<d>& world, StepContext& ctx) override;

 private:
  Stage stage_;
};

}  // namespace monolith

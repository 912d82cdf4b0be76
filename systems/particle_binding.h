#pragma once
// Deformable particles hard-bound to rigid bodies (components/deformable.h RigidBinding):
//  * binding_forces@n / @n+1 (both force evaluations): the elastic forces on bound particles
//    are added to their bodies' force and torque accumulators, so the rigid Step I / Step V
//    kicks carry them (the free particles receive the opposite forces: linear momentum is kept);
//  * follow_bound_bodies (Step IV after the rigid positions, and Step V after the rigid
//    velocities): bound particles take their bodies' pose and point velocity.
// The damping forces on bound particles, which depend on the implicit solve's velocities, are
// handed to the bodies by the solve itself (systems/deformable_dynamics.cpp).
#include "components/deformable.h"
#include "components/forces.h"
#include "components/rigid_body.h"
#include "ecs/system.h"
#include "systems/deformable_dynamics.h"

namespace monolith {

// World pose maps of the bound bodies, looked up by name (nullptr: not found).
template <int d>
std::vector<RigidBody<d>*> boundBodies(World<d>& world, const RigidBinding<d>& b);

template <int d>
class BindingForces final : public System<d> {
 public:
  explicit BindingForces(Stage s) : stage_(s) {}
  std::string name() const override { return stage_ == Stage::ForcesAtStart ? "binding_forces@n" : "binding_forces@n+1"; }
  Stage stage() const override { return stage_; }
  std::vector<std::string> reads() const override {
    return {RigidBinding<d>::kName, Particles<d>::kName, SimplexMesh<d>::kName, Elasticity::kName, RigidBody<d>::kName};
  }
  std::vector<std::string> writes() const override { return {RigidForces<d>::kName}; }
  bool needed(const World<d>& w) const override { return w.template count<RigidBinding<d>>() > 0; }
  void run(World<d>& world, StepContext& ctx) override;

 private:
  Stage stage_;
  ForceModelCache<d> cache_;
};

template <int d>
class FollowBoundBodies final : public System<d> {
 public:
  explicit FollowBoundBodies(Stage s) : stage_(s) {}
  std::string name() const override {
    return stage_ == Stage::AdvancePositions ? "follow_bound_bodies" : "follow_bound_bodies_velocity";
  }
  Stage stage() const override { return stage_; }
  std::vector<std::string> reads() const override { return {RigidBinding<d>::kName, RigidBody<d>::kName}; }
  std::vector<std::string> writes() const override { return {Particles<d>::kName}; }
  bool needed(const World<d>& w) const override { return w.template count<RigidBinding<d>>() > 0; }
  void run(World<d>& world, StepContext& ctx) override;

 private:
  Stage stage_;
};

// Sets the bound particles' positions (if `positions`) and velocities from their bodies.
template <int d>
void followBoundBodies(World<d>& world, bool positions);

}  // namespace monolith

#pragma once
// Kinematic bodies: scripted velocity from the scene, infinite mass in collisions and
// contact. The velocity of step n is the script's value at t^{n+1/2} (exact for piecewise
// constant scripts whose breaks fall on step boundaries), set before Step II; the pose is
// advanced with it in Step IV.
#include "components/kinematic.h"
#include "components/rigid_body.h"
#include "ecs/system.h"

namespace monolith {

template <int d>
class ScriptKinematicVelocity final : public System<d> {
 public:
  std::string name() const override { return "script_kinematic_velocity"; }
  Stage stage() const override { return Stage::ForcesAtStart; }
  std::vector<std::string> reads() const override { return {KinematicMotion<d>::kName}; }
  std::vector<std::string> writes() const override { return {RigidBody<d>::kName}; }
  bool needed(const World<d>& w) const override { return w.template count<KinematicMotion<d>>() > 0; }
  void run(World<d>& world, StepContext& ctx) override;
};

template <int d>
class AdvanceKinematicPositions final : public System<d> {
 public:
  std::string name() const override { return "advance_kinematic_positions"; }
  Stage stage() const override { return Stage::AdvancePositions; }
  std::vector<std::string> reads() const override { return {KinematicMotion<d>::kName}; }
  std::vector<std::string> writes() const override { return {RigidBody<d>::kName}; }
  bool needed(const World<d>& w) const override { return w.template count<KinematicMotion<d>>() > 0; }
  void run(World<d>& world, StepContext& ctx) override;
};

}  // namespace monolith

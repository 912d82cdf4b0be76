#pragma once
// The rigid collision and contact stages of the Newmark step (thesis Sec. 4.2), one
// system per stage, sharing one ContactWorkspace per step:
//   collisions               Step II  (Sec. 4.4): v^n -> \hat v^n, pairwise Gauss-Seidel, restitution
//                                     and friction, energy clamp against (x^n, v^n); then
//                                     \hat v^{n+1/2} = \hat v^n + (\tilde v^{n+1/2} - v^n)
//   contact                  Step III (Sec. 4.5): contact graph, epsilon-scaled inelastic contact on
//                                     the pairs collisions processed, level by level; no clamp
//   shock_propagation        Step III (GBF 2003 [64]): bottom-up, each level frozen after it is done
//   resolve_interpenetration Step IV  (Sec. 4.6.1, App. B): central-body push-out, then the
//                                     velocity is reset to \hat v^n (+ the Step I kick)
//   velocity_contact         Step V   (Sec. 2.3.2 "Contact Clamping"): contact again on the pairs
//                                     contact touched, clamped against (x^{n+1}, v^{n+1})
//   fall_asleep              after Step V, with sleeping on (not in the thesis; systems/sleep.h):
//                                     islands that have been still long enough are held still
#include <memory>
#include <utility>
#include <vector>

#include "ecs/system.h"
#include "solvers/contact/push_out_rounds.h"
#include "systems/contact_workspace.h"

namespace monolith {

template <int d>
class RigidContactSystem : public System<d> {
 public:
  explicit RigidContactSystem(std::shared_ptr<ContactWorkspace<d>> ws) : ws_(std::move(ws)) {}
  std::vector<std::string> reads() const override {
    return {Collider<d>::kName, Shape<d>::kName, RigidForces<d>::kName, KinematicMotion<d>::kName};
  }
  // Sleep: Step II wakes bodies (wakeTouchedSleepers), fall_asleep puts them to sleep.
  std::vector<std::string> writes() const override {
    return {RigidBody<d>::kName, "contact_workspace", Sleep<d>::kName};
  }
  bool needed(const World<d>& w) const override { return w.template count<Collider<d>>() > 0; }

 protected:
  std::shared_ptr<ContactWorkspace<d>> ws_;
};

template <int d>
class Collisions final : public RigidContactSystem<d> {
 public:
  using RigidContactSystem<d>::RigidContactSystem;
  std::string name() const override { return "collisions"; }
  Stage stage() const override { return Stage::Collisions; }
  void run(World<d>& world, StepContext& ctx) override;
};

template <int d>
class Contact final : public RigidContactSystem<d> {
 public:
  using RigidContactSystem<d>::RigidContactSystem;
  std::string name() const override { return "contact"; }
  Stage stage() const override { return Stage::Contact; }
  void run(World<d>& world, StepContext& ctx) override;
};

template <int d>
class ShockPropagation final : public RigidContactSystem<d> {
 public:
  using RigidContactSystem<d>::RigidContactSystem;
  std::string name() const override { return "shock_propagation"; }
  Stage stage() const override { return Stage::Contact; }
  bool needed(const World<d>& w) const override {
    return RigidContactSystem<d>::needed(w) && w.template resource<ContactSettings>().shockPropagation;
  }
  void run(World<d>& world, StepContext& ctx) override;
};

template <int d>
class ResolveInterpenetration final : public RigidContactSystem<d> {
 public:
  using RigidContactSystem<d>::RigidContactSystem;
  std::string name() const override { return "resolve_interpenetration"; }
  Stage stage() const override { return Stage::AdvancePositions; }
  void run(World<d>& world, StepContext& ctx) override;

 private:
  // The rotational-energy clamp on the momentum Step V starts from (3-D;
  // systems/rotational_energy_clamp.cpp): what it needs from before push-out, then the clamp
  // (returns the bodies it scaled).
  void rememberRotationalEnergy(const ContactWorkspace<d>& ws);
  int clampEnergyOfRestoredMomentum(ContactWorkspace<d>& ws);
  struct AdvancedState {
    solvers::contact::AngVec<d> L;
    Orientation<d> q;
  };
  std::vector<double> energyAtTimeN_;     // per body: the restored momentum's energy at time n
  std::vector<AdvancedState> advanced_;   // per body: Step IV's momentum and orientation
  // Push-out's rounds and the storage they keep from step to step.
  solvers::contact::PushOutRounds<d> pushOut_;
};

template <int d>
class VelocityContact final : public RigidContactSystem<d> {
 public:
  using RigidContactSystem<d>::RigidContactSystem;
  std::string name() const override { return "velocity_contact"; }
  Stage stage() const override { return Stage::AdvanceVelocity; }
  bool needed(const World<d>& w) const override {
    return RigidContactSystem<d>::needed(w) && w.template resource<ContactSettings>().velocityContact;
  }
  void run(World<d>& world, StepContext& ctx) override;
};

// Sleeping (not in the thesis; systems/sleep.h): after Step V, every dynamic body of an island
// (the bodies the step's pairs join) that has moved slower than sleep_speed for sleep_time is
// put to sleep with the others of its island, at rest.
template <int d>
class FallAsleep final : public RigidContactSystem<d> {
 public:
  using RigidContactSystem<d>::RigidContactSystem;
  std::string name() const override { return "fall_asleep"; }
  Stage stage() const override { return Stage::AdvanceVelocity; }
  bool needed(const World<d>& w) const override {
    return RigidContactSystem<d>::needed(w) && w.template count<Sleep<d>>() > 0;
  }
  void run(World<d>& world, StepContext& ctx) override;

 private:
  std::vector<double> reach_;  // per body: its farthest point's distance from its centre of mass
  std::vector<const solvers::collision::PreparedGeometry<d>*> reachOf_;  // the geometry reach_ is of
  std::vector<int> parent_;    // union-find over the step's pairs
  std::vector<char> blocked_;  // per island root: a member that may not sleep yet
  std::vector<char> held_;     // per body, then per island root: at rest without being pushed
};

// The systems above sharing one workspace, in pipeline order.
template <int d>
std::vector<std::unique_ptr<System<d>>> makeRigidContactSystems();

}  // namespace monolith

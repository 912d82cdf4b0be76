#pragma once
// Force systems of rigid bodies. Each runs at both Newmark force evaluations (Stage
// ForcesAtStart: x^n, v^n; Stage ForcesAtEnd: x^{n+1}, v^{n+1/2}). They all write the
// `rigid_forces` accumulator, so the scheduler serializes them in registration order:
// clear first, then gravity, external forces, then plugin forces.
#include <memory>
#include <string>
#include <vector>

#include "components/forces.h"
#include "components/rigid_body.h"
#include "ecs/system.h"

namespace monolith {

// Base for a rigid force evaluated at one of the two force stages.
template <int d>
class RigidForceSystem : public System<d> {
 public:
  RigidForceSystem(std::string baseName, Stage stage) : baseName_(std::move(baseName)), stage_(stage) {}
  std::string name() const override {
    return baseName_ + (stage_ == Stage::ForcesAtStart ? "@n" : "@n+1");
  }
  Stage stage() const override { return stage_; }

 private:
  std::string baseName_;
  Stage stage_;
};

// Makes one instance per force stage: what a SystemType::create returns for a force.
template <class S, int d>
std::vector<std::unique_ptr<System<d>>> atBothForceStages() {
  std::vector<std::unique_ptr<System<d>>> out;
  out.push_back(std::make_unique<S>(Stage::ForcesAtStart));
  out.push_back(std::make_unique<S>(Stage::ForcesAtEnd));
  return out;
}

template <int d>
class ClearRigidForces final : public RigidForceSystem<d> {
 public:
  explicit ClearRigidForces(Stage s) : RigidForceSystem<d>("clear_rigid_forces", s) {}
  std::vector<std::string> reads() const override { return {}; }
  std::vector<std::string> writes() const override { return {RigidForces<d>::kName}; }
  bool needed(const World<d>& w) const override { return w.template count<RigidForces<d>>() > 0; }
  void run(World<d>& world, StepContext& ctx) override;
};

// m g on every dynamic body (gravity from the scene's top-level "gravity").
template <int d>
class GravityForce final : public RigidForceSystem<d> {
 public:
  explicit GravityForce(Stage s) : RigidForceSystem<d>("gravity", s) {}
  std::vector<std::string> reads() const override { return {RigidBody<d>::kName}; }
  std::vector<std::string> writes() const override { return {RigidForces<d>::kName}; }
  bool needed(const World<d>& w) const override {
    return w.template count<RigidForces<d>>() > 0 && w.settings().gravity.squaredNorm() > 0;
  }
  void run(World<d>& world, StepContext& ctx) override;
};

template <int d>
class ExternalForces final : public RigidForceSystem<d> {
 public:
  explicit ExternalForces(Stage s) : RigidForceSystem<d>("external_forces", s) {}
  std::vector<std::string> reads() const override { return {ExternalForce<d>::kName}; }
  std::vector<std::string> writes() const override { return {RigidForces<d>::kName}; }
  bool needed(const World<d>& w) const override {
    return w.template count<ExternalForce<d>>() > 0 && w.template count<RigidForces<d>>() > 0;
  }
  void run(World<d>& world, StepContext& ctx) override;
};

}  // namespace monolith

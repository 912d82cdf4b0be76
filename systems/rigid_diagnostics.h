#pragma once
// Measures the state at t^{n+1} for metrics.csv: kinetic energy (translational + rotational),
// gravitational potential energy -m g.x, linear momentum and angular momentum about the
// origin (x cross m v + L). Static bodies carry no energy or momentum.
#include "components/rigid_body.h"
#include "ecs/system.h"

namespace monolith {

struct RigidTotals {
  double kinetic = 0, potential = 0;
  Eigen::Vector3d linearMomentum = Eigen::Vector3d::Zero();
  Eigen::Vector3d angularMomentum = Eigen::Vector3d::Zero();
};

// Totals over all dynamic bodies, summed serially in pool order (deterministic).
template <int d>
RigidTotals measureRigidTotals(const World<d>& world);

template <int d>
class RigidDiagnostics final : public System<d> {
 public:
  std::string name() const override { return "rigid_diagnostics"; }
  Stage stage() const override { return Stage::Diagnostics; }
  std::vector<std::string> reads() const override { return {RigidBody<d>::kName}; }
  std::vector<std::string> writes() const override { return {"diagnostics"}; }
  bool needed(const World<d>& w) const override { return w.template count<RigidBody<d>>() > 0; }
  void run(World<d>& world, StepContext& ctx) override;
};

}  // namespace monolith

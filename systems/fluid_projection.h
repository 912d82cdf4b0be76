#pragma once
// Step V for the fluid (thesis Sec. 5.7, eq. 5.31): the coupled SPD pressure-viscosity solve
//   [[G^T b G, G^T b G_mu^T], [G_mu b G, I + G_mu b G_mu^T]] (p_hat, u_hat) = (G^T u*, G_mu u*)
// and u^{n+1} = u* - b (G p_hat + G_mu^T u_hat), b = beta^-1 = 1/(rho V); or, when the scene
// asks for it, Chorin's splitting (implicit viscosity, then the pressure Poisson projection).
// Reports solver iterations and residual, the divergence after projection, the fluid's kinetic
// energy and momentum, and the velocity change per time (the steady-state measure).
#include <memory>

#include "components/fluid_coupling.h"
#include "components/mac_grid.h"
#include "ecs/system.h"

namespace monolith {

template <int d>
class FluidProjection final : public System<d> {
 public:
  FluidProjection();
  ~FluidProjection() override;
  std::string name() const override { return "project_fluid"; }
  Stage stage() const override { return Stage::AdvanceVelocity; }
  std::vector<std::string> reads() const override { return {FluidMaterial::kName}; }
  std::vector<std::string> writes() const override { return {MacGrid<d>::kName, "diagnostics"}; }
  // With two-way coupled bodies project_fluid_structure solves the fluid with them instead.
  bool needed(const World<d>& w) const override {
    return w.template count<MacGrid<d>>() > 0 && w.template count<FluidCoupling<d>>() == 0;
  }
  void run(World<d>& world, StepContext& ctx) override;

 private:
  struct Cache;  // operators and preconditioner, reused while dt and the geometry are unchanged
  std::unique_ptr<Cache> cache_;
};

}  // namespace monolith

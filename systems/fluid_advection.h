#pragma once
// Fluid advection (thesis Sec. 5.4, step 6; Sec. 5.2): u* = u^n - dt (u^n . grad) u^n by the
// scene's scheme, semi-Lagrangian (with clipping at solids), MacCormack, or 3rd-order ENO /
// 5th-order WENO with TVD RK3.
// Skipped for unsteady Stokes flow ("advection": "none"). Limits the step by the CFL condition.
#include "components/mac_grid.h"
#include "ecs/system.h"
#include "solvers/fluid/fluid_settings.h"

namespace monolith {

template <int d>
class FluidAdvection final : public System<d> {
 public:
  std::string name() const override { return "advect_fluid"; }
  Stage stage() const override { return Stage::Advection; }
  std::vector<std::string> reads() const override { return {}; }
  std::vector<std::string> writes() const override { return {MacGrid<d>::kName}; }
  bool needed(const World<d>& w) const override {
    return w.template count<MacGrid<d>>() > 0 &&
           w.template resource<FluidSolverSettings>().advection != FluidSolverSettings::Advection::None;
  }
  void run(World<d>& world, StepContext& ctx) override;
  double unitCflDt(const World<d>& world) const override;  // dx / max|u|
};

// Gravity on the fluid (Sec. 5.4 step 6: + dt f / rho with f = rho g), added to u* on the free
// faces before the projection.
template <int d>
class FluidGravity final : public System<d> {
 public:
  std::string name() const override { return "fluid_gravity"; }
  Stage stage() const override { return Stage::ForcesAtEnd; }
  std::vector<std::string> reads() const override { return {}; }
  std::vector<std::string> writes() const override { return {MacGrid<d>::kName}; }
  bool needed(const World<d>& w) const override {
    return w.template count<MacGrid<d>>() > 0 && w.settings().gravity.squaredNorm() > 0;
  }
  void run(World<d>& world, StepContext& ctx) override;
};

}  // namespace monolith

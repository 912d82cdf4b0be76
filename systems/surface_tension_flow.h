#pragma once
// The whole fluid step of thesis Ch. 6 for a TwoPhaseFlow: advection, gravity, the explicit
// surface-tension force, the coupled SPD solve (6.33) with the implicit surface-tension rows C H,
// the front's move x^{n+1} = x^n + dt H u^{n+1} and its remeshing (solvers/surface_tension).
// Reports per step: fluid_max_speed, fluid_cfl, capillary_dt (Brackbill's limit), its ratio to dt,
// the pressure jump, the front's area drift and point count, the CG iterations and the probes.
// The blow-up guard: a step whose speed exceeds the component's blow_up_speed (or whose front left
// the domain) reports the diagnostic surface_tension_<implicit|explicit>_blew_up as NaN, which the
// runner turns into an "unstable" stop naming it, and prints the reason on stderr.
#include "components/two_phase_flow.h"
#include "ecs/system.h"

namespace monolith {

template <int d>
class SurfaceTensionFlow final : public System<d> {
 public:
  std::string name() const override { return "surface_tension_flow"; }
  Stage stage() const override { return Stage::AdvanceVelocity; }
  std::vector<std::string> reads() const override { return {}; }
  std::vector<std::string> writes() const override { return {TwoPhaseFlow<d>::kName, "diagnostics"}; }
  bool needed(const World<d>& w) const override { return w.template count<TwoPhaseFlow<d>>() > 0; }
  void run(World<d>& world, StepContext& ctx) override;
};

}  // namespace monolith

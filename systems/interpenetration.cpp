// Step IV item 2 (thesis Sec. 4.6.1, Appendix B; notes 1.7): interpenetration resolution after
// the positions have been advanced to \hat x^{n+1}. This system sequences the stage: the bodies
// re-based where Step IV put them, push-out's rounds (solvers/contact/push_out_rounds.h, on the
// contact workspace as their host), then the velocity reset to the post-collision \hat v^n plus
// the Step I kick, so that Step V's half kick completes the trapezoid update from \hat v^n (the
// contact impulses of Step III only served the positions; push-out leaves momenta unchanged,
// App. B.1), the rotational-energy clamp (systems/rotational_energy_clamp.cpp), the jointed
// bodies' positions (systems/articulation.h) and the metrics.
#include "components/joint.h"
#include "solvers/contact/push_out_rounds_impl.h"
#include "systems/articulation.h"
#include "systems/push_out_host.h"
#include "systems/rigid_contact.h"

namespace monolith {

namespace con = solvers::contact;

template <int d>
void ResolveInterpenetration<d>::run(World<d>& world, StepContext& ctx) {
  ContactWorkspace<d>& ws = *this->ws_;
  if (ws.bodies.empty()) return;
  const bool clampRotation = d == 3 && ws.settings.energyClamp;
  if (clampRotation) rememberRotationalEnergy(ws);
  // Where Step IV put the moving bodies (a static one keeps pack's pose: its collision
  // geometry's centre, which for a grounded box is not the body's, grounded_box.h).
  for (auto& b : ws.bodies)
    if (!b.still()) PushOutHost<d>::setBasePose(b, b.body->x, b.body->orientation);
  PushOutHost<d> host(ws);
  const con::PushOutReport r = pushOut_.run(host, ws.settings);

  for (auto& b : ws.bodies) {
    if (b.immovable()) continue;
    b.v = b.vCollided + b.dv;
    b.L = b.LCollided + b.dL;
  }
  ctx.diagnostics.set("rotation_energy_clamps", clampRotation ? clampEnergyOfRestoredMomentum(ws) : 0);
  // Jointed bodies: their poses come from the joints and contacts together (systems/articulation.h).
  if (world.template count<ArticulationJoint<d>>() > 0) resolveJointedInterpenetration(world, ws, ctx);
  ws.unpack(true);
  ctx.diagnostics.set("push_out_solves", r.solves);
  ctx.diagnostics.set("push_out_new_overlaps", r.newOverlaps);
  ctx.diagnostics.set("push_out_rounds", r.rounds);
  ctx.diagnostics.set("push_out_rounds_undone", r.roundsUndone);
  // Joint passes over a jam that were kept (each left it shallower than the pass before).
  ctx.diagnostics.set("push_out_joint_passes", r.jointPasses);
  // Joint solves again with more rings (a jam left deeper than pushOutJointRegrowOverlap).
  ctx.diagnostics.set("push_out_joint_regrowths", r.jointRegrowths);
  ctx.diagnostics.set("push_out_overlaps_found_after", r.overlapsFoundAfter);
  ctx.diagnostics.set("broad_phase_pairs_added_in_push_out", r.pairsAdded);
  ctx.diagnostics.set("max_penetration", r.maxPenetration);
  ctx.diagnostics.set("max_penetration_ratio", r.maxPenetrationRatio);
}

template class ResolveInterpenetration<2>;
template class ResolveInterpenetration<3>;

}  // namespace monolith

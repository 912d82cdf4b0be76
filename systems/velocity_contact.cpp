// Step V item 4 (thesis Sec. 4.7; notes 1.3 "post-CG constraints"): contact again, after the
// velocity update, on the pairs that received contact impulses in Step III. The split state is
// (x^{n+2} = x^{n+1} + dt v^{n+1}, v^{n+1}); impulses are clamped against the non-split state
// (x^{n+1}, v^{n+1}) (Sec. 2.3.2 "Contact Clamping"), so this step never adds kinetic energy.
#include <algorithm>

#include "components/joint.h"
#include "systems/articulation.h"
#include "systems/rigid_contact.h"

namespace monolith {

template <int d>
void VelocityContact<d>::run(World<d>& world, StepContext& ctx) {
  ContactWorkspace<d>& ws = *this->ws_;
  if (ws.bodies.empty()) return;
  // Keep pairs, levels and islands of this step; re-base the bodies at time n+1.
  std::vector<ContactPairState> pairs = ws.pairs;
  if (!ws.pack(world, ctx.dt, /*subtractKick=*/false)) return;
  ws.pairs = std::move(pairs);
  const ContactSettings& s = ws.settings;
  const CandidateStep step{ctx.dt, /*kick=*/false};  // from x^{n+1} with v^{n+1}
  const auto energyBefore = ws.readEnergy();
  // Joints (systems/articulation.h): the jointed bodies' velocities first projected onto their
  // joints and contacts together (with friction, while the contacts still carry the weight).
  if (jointContactRounds(world) > 0) {
    postStabilizeWithContacts(world, ws, ctx);
    ws.reloadVelocities();
  }
  std::vector<int> impulses(ws.islands.members.size(), 0), clamps(ws.islands.members.size(), 0);
  std::vector<double> change(ws.islands.members.size(), 0.0);
  ws.forEachIsland([&](int island) {
    impulses[island] =
        ws.contactSweeps(island, ImpulseMode::ClampedContact, step, true, &change[island], &clamps[island]);
    // Shock propagation here too (not in the thesis's Step V): the sweeps end with the top
    // levels, whose last impulses push the lower bodies down, so a resting stack would keep a
    // downward velocity of the order of dt g / levels. A bottom-up pass with each level frozen
    // leaves it at rest; its impulses are clamped like the others.
    if (s.shockPropagation)
      impulses[island] +=
          ws.propagateShock(island, ImpulseMode::ClampedContact, step, true, &change[island], &clamps[island]);
  });
  // Then rounds of post-stabilization and contact again, so that neither leaves the other a
  // velocity to undo; post_stabilize_velocities closes the joints last.
  for (int round = 0, rounds = jointContactRounds(world); round < rounds; ++round) {
    ws.unpack(false);
    postStabilizeJointVelocities(world, ctx);
    ws.reloadVelocities();
    ws.updateAllCandidates(step);
    ws.forEachIsland([&](int island) {
      impulses[island] +=
          ws.contactSweeps(island, ImpulseMode::ClampedContact, step, true, &change[island], &clamps[island]);
      if (s.shockPropagation)
        impulses[island] +=
            ws.propagateShock(island, ImpulseMode::ClampedContact, step, true, &change[island], &clamps[island]);
    });
  }
  const auto energyAfter = ws.readEnergy();
  // The whole step's energy (systems/step_energy_clamp.cpp); measured after the diagnostics
  // above, which are about this stage's impulses alone.
  double clampRemoved = 0;
  const int clampedIslands = s.stepEnergyClamp ? ws.clampStepEnergyGain(world, clampRemoved) : 0;
  ws.unpack(false);
  if (s.stepEnergyClamp) {
    ctx.diagnostics.set("step_energy_clamped_islands", clampedIslands);
    ctx.diagnostics.set("step_energy_clamp_removed", clampRemoved);
  }
  int total = 0, clampCount = 0;
  for (int n : impulses) total += n;
  for (int n : clamps) clampCount += n;
  ctx.diagnostics.set("velocity_contact_impulses", total);
  ctx.diagnostics.set("velocity_contact_energy_clamps", clampCount);
  ContactWorkspace<d>::reportEnergyChange(ctx.diagnostics, "velocity_contact_energy_change", energyBefore,
                                          energyAfter);
}

template <int d>
std::vector<std::unique_ptr<System<d>>> makeRigidContactSystems() {
  auto ws = std::make_shared<ContactWorkspace<d>>();
  std::vector<std::unique_ptr<System<d>>> v;
  v.push_back(std::make_unique<Collisions<d>>(ws));
  v.push_back(std::make_unique<Contact<d>>(ws));
  v.push_back(std::make_unique<ShockPropagation<d>>(ws));
  v.push_back(std::make_unique<ResolveInterpenetration<d>>(ws));
  v.push_back(std::make_unique<VelocityContact<d>>(ws));
  v.push_back(std::make_unique<FallAsleep<d>>(ws));
  return v;
}

template class VelocityContact<2>;
template class VelocityContact<3>;
template std::vector<std::unique_ptr<System<2>>> makeRigidContactSystems<2>();
template std::vector<std::unique_ptr<System<3>>> makeRigidContactSystems<3>();

}  // namespace monolith

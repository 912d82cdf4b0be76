// Step III of the Newmark step (thesis Sec. 4.5; notes 1.6): contact on the pairs collisions
// processed, in contact-graph order from the bottom level up, with restitution -1 + eps where
// eps ramps to 1 over the sweeps (early sweeps remove only part of the approach velocity, the
// last one is fully inelastic). The candidate positions are x^n + dt v^{n+1/2}. Not clamped
// (Sec. 2.3.2: clamping this split state against (x^n, v^n) makes resting stacks jitter).
#include <array>
#include <utility>
#include <vector>

#include "components/joint.h"
#include "systems/articulation.h"
#include "systems/rigid_contact.h"

namespace monolith {

template <int d>
void Contact<d>::run(World<d>& world, StepContext& ctx) {
  ContactWorkspace<d>& ws = *this->ws_;
  if (ws.bodies.empty()) return;
  // Joint post-stabilization (Step II.2) and PD (Step III.2) ran since collisions unpacked.
  if (world.template count<ArticulationJoint<d>>() > 0) {
    ws.reloadVelocities();
    // Where Step III's joint-and-contact projection after shock propagation starts from.
    if (articulationSettings(world).stepThreeContactSolve) {
      ws.stepThreeStartV.resize(ws.bodies.size());
      ws.stepThreeStartL.resize(ws.bodies.size());
      for (std::size_t i = 0; i < ws.bodies.size(); ++i)
        ws.stepThreeStartV[i] = ws.bodies[i].v, ws.stepThreeStartL[i] = ws.bodies[i].L;
    }
  }
  const CandidateStep step{ctx.dt, /*kick=*/false};  // the working velocity is v^{n+1/2}
  ws.updateAllCandidates(step);
  std::vector<int> impulses(ws.islands.members.size(), 0);
  ws.forEachIsland([&](int island) {
    impulses[island] = ws.contactSweeps(island, ImpulseMode::Contact, step, false, nullptr, nullptr);
  });
  ws.unpack(false);
  // Joints (systems/articulation.h): rounds of pre-stabilization, then contact again, so that
  // contact has the last word and the joints close on what it leaves (Sec. 4.5).
  std::vector<std::pair<double, std::array<double, 3>>> stageSums;
  for (int round = 0, rounds = jointContactRounds(world); round < rounds; ++round) {
    preStabilizeJointVelocities(world, ctx);
    ws.reloadVelocities();
    ws.updateAllCandidates(step);
    // The rounds' sweeps go on with Step III's stage: its sums (ContactPairState::stageNormal)
    // keep the first sweeps' impulses, which carry the bodies' weight, so that shock
    // propagation's friction leans on them (contactSweeps starts the sums anew). Leaning on
    // the last round's alone, shock propagation let the limbs of a resting ragdoll pile roll
    // and slide by 1.8 cm a second (4 ragdolls, 3-4 s), 1.2 cm with the whole stage.
    stageSums.assign(ws.pairs.size(), {});
    for (std::size_t k = 0; k < ws.pairs.size(); ++k)
      stageSums[k] = {ws.pairs[k].stageNormal, ws.pairs[k].stageFriction};
    ws.forEachIsland([&](int island) {
      impulses[island] += ws.contactSweeps(island, ImpulseMode::Contact, step, false, nullptr, nullptr);
    });
    for (std::size_t k = 0; k < ws.pairs.size(); ++k) {
      ws.pairs[k].stageNormal += stageSums[k].first;
      for (int c = 0; c < 3; ++c) ws.pairs[k].stageFriction[c] += stageSums[k].second[c];
    }
    ws.unpack(false);
  }
  int total = 0;
  for (int n : impulses) total += n;
  ctx.diagnostics.set("contact_impulses", total);
}

// Shock propagation (Guendelman, Bridson & Fedkiw 2003; notes 1.6): one more bottom-up pass;
// after a level is processed its bodies are frozen (infinite mass), so the bodies above cannot
// push them back down. Everything is unfrozen at the end.
template <int d>
void ShockPropagation<d>::run(World<d>& world, StepContext& ctx) {
  ContactWorkspace<d>& ws = *this->ws_;
  if (ws.bodies.empty()) return;
  const CandidateStep step{ctx.dt, /*kick=*/false};
  std::vector<int> impulses(ws.islands.members.size(), 0);
  ws.forEachIsland([&](int island) {
    impulses[island] = ws.propagateShock(island, ImpulseMode::Contact, step, false, nullptr, nullptr);
  });
  ws.unpack(false);
  // Joints (systems/articulation.h): the jointed bodies' velocities onto their joints and
  // contacts together, where the scene asks for it.
  if (world.template count<ArticulationJoint<d>>() > 0 && articulationSettings(world).stepThreeContactSolve) {
    preStabilizeWithContacts(world, ws, ctx);
    ws.reloadVelocities();
    ws.updateAllCandidates(step);
  }
  int total = 0;
  for (int n : impulses) total += n;
  ctx.diagnostics.set("shock_propagation_impulses", total);
}

template class Contact<2>;
template class Contact<3>;
template class ShockPropagation<2>;
template class ShockPropagation<3>;

}  // namespace monolith

// Step II of the Newmark step (thesis Sec. 4.4; notes 1.3-1.5): collisions with time-n
// velocities, so bodies resting in contact do not bounce; candidate positions
// x^n + dt (v + (\tilde v^{n+1/2} - v^n)) are re-advanced after every impulse (Gauss-Seidel).
#include <algorithm>

#include "systems/rigid_contact.h"

namespace monolith {

template <int d>
void Collisions<d>::run(World<d>& world, StepContext& ctx) {
  ContactWorkspace<d>& ws = *this->ws_;
  if (!ws.pack(world, ctx.dt, /*subtractKick=*/true)) return;
  ws.findPairs();
  const int woken = ws.wakeTouchedSleepers(world, ctx.dt);  // sleeping on (systems/sleep.h), else 0
  if (ws.settings.stepEnergyClamp) ws.rememberStepStart(world);
  const auto energyBefore = ws.readEnergy();

  // The candidates move with v^n plus the Step I increment (pack recovered v^n).
  const CandidateStep step{ctx.dt, /*kick=*/true};
  std::vector<int> impulses(ws.islands.members.size(), 0), clamps(ws.islands.members.size(), 0);
  std::vector<double> clampChange(ws.islands.members.size(), 0.0);
  ws.forEachIsland([&](int island) {
    for (int sweep = 0; sweep < ws.settings.collisionIterations; ++sweep) {
      const int n = ws.collisionSweep(island, sweep, step, &clampChange[island], &clamps[island]);
      impulses[island] += n;
      if (n == 0) break;
    }
  });

  const auto energyAfter = ws.readEnergy();
  for (auto& b : ws.bodies) {
    b.vCollided = b.v;
    b.LCollided = b.L;
  }
  const int pairsAdded = ws.computeLevels(ctx.dt);
  // Step II item 3: \hat v^{n+1/2} = \hat v^n + (\tilde v^{n+1/2} - v^n).
  for (auto& b : ws.bodies) {
    if (b.infinite()) continue;
    b.v += b.dv;
    b.L += b.dL;
  }
  ws.unpack(false);  // from here on the working velocity is the n+1/2 one: no kick

  int processed = 0, swept = 0, impulseCount = 0, clampCount = 0;
  for (const auto& p : ws.pairs) {
    processed += p.processed ? 1 : 0;
    swept += p.swept ? 1 : 0;
  }
  for (int n : impulses) impulseCount += n;
  ws.lastCollisionImpulses = impulseCount;
  for (int n : clamps) clampCount += n;
  auto& out = ctx.diagnostics;
  out.set("contact_pairs_broad_phase", static_cast<double>(ws.pairs.size()));
  // Pairs the broad phase found again where the collision impulses sent the bodies.
  out.set("broad_phase_pairs_added_after_collisions", pairsAdded);
  out.set("collision_pairs_processed", processed);
  out.set("collision_pairs_swept", swept);  // fast pairs met where they first touch (swept_contact.h)
  out.set("collision_impulses", impulseCount);
  out.set("collision_energy_clamps", clampCount);
  if (world.template count<Sleep<d>>() > 0) out.set("bodies_woken", woken);
  out.set("contact_islands", static_cast<double>(ws.islands.members.size()));
  out.set("contact_levels", ws.levels.count());
  // Kinetic energy of the time-n state before and after the collision impulses (Sec. 2.3.2:
  // the clamp keeps it from rising; in the elevator's frame when a kinematic body lifts the others).
  ContactWorkspace<d>::reportEnergyChange(out, "collision_energy_change", energyBefore, energyAfter);
}

template class Collisions<2>;
template class Collisions<3>;

}  // namespace monolith

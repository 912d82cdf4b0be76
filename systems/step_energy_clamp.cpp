// The step energy clamp (not in the thesis; ContactSettings::stepEnergyClamp). The thesis
// clamps the collision impulses against (x^n, v^n) and the second contact step's against
// (x^{n+1}, v^{n+1}), but not the first contact step (Sec. 2.3.2, "Contact Clamping": clamping
// it against (x^n, v^n) makes resting contact jitter; "future work"). That step's velocities
// only move the positions and are then thrown away, so an impulse that turns a spinning body's
// fall into a rise lifts it without taking the kinetic energy the lift costs: without this
// clamp, on the short schedule with its one inelastic contact pass, about one random 2-D drop in
// 600 gains 0.4-1 % of its total energy in one step (2-D drops 261 and 736,
// docs/benchmarks_rigid_contact.md).
//
// The clamp checks the whole step instead. Under gravity alone the Newmark step keeps the
// energy E = KE - m g.x exactly (Step I's and Step V's half kicks pay for the fall), collision
// impulses never add kinetic energy, so an island of bodies that only gravity and contact moved
// must not end the step with more energy than it began with because it was lifted. Where it
// does, every velocity and angular momentum of the island is scaled by one factor s in [0, 1]
// with (1 - s^2) KE^{n+1} = min(rise, lift): the non-penetration rows v_n >= 0 against the
// static bodies hold
// for the scaled velocities too (they are homogeneous). Only islands that touch a static or
// sleeping body are clamped (in free flight scaling would change the island's momentum), and
// only in scenes of rigid bodies alone (particles, fluids and joints exchange energy the island
// sum does not see).
#include <cmath>

#include "components/deformable.h"
#include "components/mac_grid.h"
#include "systems/contact_workspace.h"

namespace monolith {

template <int d>
bool ContactWorkspace<d>::gravityOnly(World<d>& world, std::size_t i) const {
  const ContactBody<d>& b = bodies[i];
  if (b.infinite()) return false;
  const auto* forces = world.template findPool<RigidForces<d>>();
  const RigidForces<d>* f = forces ? forces->get(entities_[i]) : nullptr;
  if (!f) return gravity.isZero(0);
  return f->force == b.mass * gravity && f->torque.isZero(0);
}

template <int d>
void ContactWorkspace<d>::rememberStepStart(World<d>& world) {
  stepStart_.resize(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    StepStart& s = stepStart_[i];
    s.x = bodies[i].x0;
    s.kinetic = bodies[i].kineticEnergy();
    s.gravityOnly = gravityOnly(world, i);
  }
}

template <int d>
int ContactWorkspace<d>::clampStepEnergyGain(World<d>& world, double& removed) {
  if (stepStart_.size() != bodies.size()) return 0;
  if (world.template count<Particles<d>>() > 0 || world.template count<MacGrid<d>>() > 0) return 0;
  std::vector<char> jointed(bodies.size(), 0);
  for (const auto& [a, b] : jointedPairs_) jointed[a] = jointed[b] = 1;
  const int n = static_cast<int>(islands.members.size());
  std::vector<char> grounded(n, 0), excluded(n, 0);
  for (int island = 0; island < n; ++island) {
    for (int k : islands.pairs[island]) {
      const ContactBody<d>& A = bodies[pairs[k].a];
      const ContactBody<d>& B = bodies[pairs[k].b];
      if (A.kinematic || B.kinematic) excluded[island] = 1;
      if (A.still() || B.still()) grounded[island] = 1;
    }
  }
  std::vector<int> scaled(n, 0);
  std::vector<double> taken(n, 0.0);
  // Islands share no finite body: each writes only its own members.
  forEachIsland([&](int island) {
    if (excluded[island] || !grounded[island]) return;
    double rise = 0, lift = 0, scale = 0, kinetic = 0, weight = 0;
    for (int m : islands.members[island]) {
      const ContactBody<d>& b = bodies[m];
      if (b.infinite()) continue;
      if (jointed[m] || !stepStart_[m].gravityOnly || !gravityOnly(world, m)) return;
      const double k = b.kineticEnergy();
      // The potential energy's change from the displacement itself (no cancellation of two
      // large potentials).
      const double potential = -b.mass * gravity.dot(b.x0 - stepStart_[m].x);
      rise += k - stepStart_[m].kinetic + potential;
      lift += potential;
      scale += k + stepStart_[m].kinetic + std::abs(potential);
      kinetic += k;
      weight += b.mass * gravity.norm();
    }
    // Only a rise the island's lift accounts for is taken back. A body held where it is by a
    // contact (or a gap it cannot close in one step) ends every step with Step V's half kick of
    // kinetic energy that the next collision stage removes (the thesis's own bookkeeping);
    // taking that back would stop it in the air, short of its support.
    rise = std::min(rise, lift);
    // Nor a rise below the island's weight times the contact thickness: push-out lifts resting
    // piles by about its tolerance every step, and stopping them for it (their kinetic energy is
    // about that small) takes the approach from the next step's collision stage, whose pairs
    // then go unprocessed into contact (2-D drops 5-14 % deep in one step, 6 of 1885).
    if (!(rise > settings.thickness * weight) || !(rise > 1e-12 * scale) || kinetic <= 0) return;
    const double s = std::sqrt(std::max(0.0, 1.0 - rise / kinetic));
    for (int m : islands.members[island]) {
      ContactBody<d>& b = bodies[m];
      if (b.infinite()) continue;
      b.v *= s;
      b.L *= s;
    }
    scaled[island] = 1;
    taken[island] = (1 - s * s) * kinetic;
  });
  int count = 0;
  for (int island = 0; island < n; ++island) {
    count += scaled[island];
    removed += taken[island];
  }
  return count;
}

template void ContactWorkspace<2>::rememberStepStart(World<2>&);
template void ContactWorkspace<3>::rememberStepStart(World<3>&);
template int ContactWorkspace<2>::clampStepEnergyGain(World<2>&, double&);
template int ContactWorkspace<3>::clampStepEnergyGain(World<3>&, double&);
template bool ContactWorkspace<2>::gravityOnly(World<2>&, std::size_t) const;
template bool ContactWorkspace<3>::gravityOnly(World<3>&, std::size_t) const;

}  // namespace monolith

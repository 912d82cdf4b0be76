// The clamp on the rotational energy of the momentum each body keeps after push-out
// (ResolveInterpenetration, systems/interpenetration.cpp; 3-D, not in the thesis).
#include <cmath>

#include "systems/rigid_contact.h"

namespace monolith {

namespace {

// Whether a body's rotational energy depends on its orientation: only in 3-D, and not for a
// round inertia (a cube's, a sphere's).
template <int d>
bool turningChangesEnergy(const ContactBody<d>& b) {
  if constexpr (d == 3) {
    if (b.immovable() || b.turnFree) return false;
    const auto& I = b.body->inertiaBodyInverse;
    return !(I.isDiagonal(0) && I(0, 0) == I(1, 1) && I(1, 1) == I(2, 2));
  } else {
    (void)b;
    return false;
  }
}

}  // namespace

// A clamp on the rotational energy of the momentum a body keeps (3-D; not in the thesis).
// Step IV turns each body with the momentum contact left it (Step III), and its energy fix
// (Sec. 2.2) keeps that momentum's energy; push-out then turns bodies further. The step ends by
// restoring the post-collision momentum (notes 1.3, item 9), whose energy in the new
// orientation can be far above its energy in the time-n one when the inertia is far from round:
// without this clamp a spinning needle in a random scene comes out of one step with 3.9 times
// its rotational energy after a contact impulse, and push-out's turns add energy the same way
// (2.8 % of the scene's total energy in all). Where the restored momentum has more than 5 % more energy
// in the new orientation than in the time-n one, it is scaled down to the time-n energy
// (Sec. 2.3.2's rule: an energy gain is clamped, a loss left).
// - Below 5 % nothing is done: resting and tumbling bodies gain and lose a little this way
//   all the time (in `mixed_pile` at most 1.2 %, in sliver drops 99 % of the cases under
//   1.6 %), and clamping each of those too makes the chaotic piles' overlaps worse in the
//   sliver-drop tests, while without it the energy stays within 0.1 %.
// - Turning the body instead, as the energy fix of Sec. 2.2 does, keeps the momentum but needs
//   large turns where the momentum is tiny (a body at rest in a pile), which make new overlaps
//   in `mixed_pile` (1.9 % of a body); the scaling moves nothing.
// Bodies that neither contact nor push-out turned differently are already fixed and skipped,
// and so are bodies whose rotational energy does not depend on their orientation.
template <int d>
void ResolveInterpenetration<d>::rememberRotationalEnergy(const ContactWorkspace<d>& ws) {
  // Before push-out re-bases the bodies: inverseInertia0 is still the time-n one (Step II's
  // pack), body->L the momentum Step IV turned the body with, body->orientation where it did.
  energyAtTimeN_.assign(ws.bodies.size(), 0.0);
  advanced_.resize(ws.bodies.size());
  for (std::size_t i = 0; i < ws.bodies.size(); ++i) {
    const ContactBody<d>& b = ws.bodies[i];
    if (!turningChangesEnergy(b)) continue;
    const auto kept = b.LCollided + b.dL;
    energyAtTimeN_[i] = 0.5 * kept.dot(b.inverseInertia0 * kept);
    advanced_[i] = {b.body->L, b.body->orientation};
  }
}

// The restored momentum's energy gain (relative) that is left alone (see above).
constexpr double kRotationGainAllowed = 0.05;

template <int d>
int ResolveInterpenetration<d>::clampEnergyOfRestoredMomentum(ContactWorkspace<d>& ws) {
  if constexpr (d == 3) {
    int clamped = 0;
    for (std::size_t i = 0; i < ws.bodies.size(); ++i) {
      ContactBody<d>& b = ws.bodies[i];
      if (!turningChangesEnergy(b)) continue;
      if (b.L == advanced_[i].L && b.q0.coeffs() == advanced_[i].q.coeffs()) continue;
      // inverseInertia0 is push-out's last base pose: the final orientation.
      const double energy = 0.5 * b.L.dot(b.inverseInertia0 * b.L);
      if (!(energy > energyAtTimeN_[i] * (1 + kRotationGainAllowed))) continue;
      b.L *= std::sqrt(energyAtTimeN_[i] / energy);
      ++clamped;
    }
    return clamped;
  } else {
    (void)ws;
    return 0;
  }
}

template void ResolveInterpenetration<2>::rememberRotationalEnergy(const ContactWorkspace<2>&);
template void ResolveInterpenetration<3>::rememberRotationalEnergy(const ContactWorkspace<3>&);
template int ResolveInterpenetration<2>::clampEnergyOfRestoredMomentum(ContactWorkspace<2>&);
template int ResolveInterpenetration<3>::clampEnergyOfRestoredMomentum(ContactWorkspace<3>&);

}  // namespace monolith

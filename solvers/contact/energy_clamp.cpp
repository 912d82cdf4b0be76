// Energy clamping of an impulse against a non-split reference state, thesis Sec. 2.3.2.
#include "solvers/contact/energy_clamp.h"

namespace monolith::solvers::contact {

namespace {

// One body's share of KE' - KE = s * linear + s^2/2 * quadratic for the linear impulse jLinear
// and angular impulse jAngular on it. p^T m^{-1} jLinear = v . jLinear; a body of infinite mass
// contributes nothing (its terms vanish in the thesis's formula; a kinematic partner's motion is
// already folded into the other body's relative velocity by the caller).
template <int d>
void addBodyTerms(const ClampBody<d>& body, const Vec<d>& jLinear, const AngVec<d>& jAngular,
                  double& linear, double& quadratic) {
  if (body.inverseMass > 0) {
    linear += jLinear.dot(body.velocity);
    quadratic += body.inverseMass * jLinear.squaredNorm();
  }
  const AngVec<d> iInvJ = body.inverseInertia * jAngular;
  linear += iInvJ.dot(body.angularMomentum);  // j_tau^T I^{-1} L (I^{-1} symmetric)
  quadratic += jAngular.dot(iInvJ);
}

}  // namespace

template <int d>
ClampResult clampImpulseEnergy(const ClampBody<d>& a, const ClampBody<d>& b, const Vec<d>& j,
                               const AngVec<d>& pureTorque) {
  // A receives (j, r_A x j + j_tau); B the negation at its own lever arm.
  const AngVec<d> jTauA = cross<d>(a.r, j) + pureTorque;
  const AngVec<d> jTauB = -cross<d>(b.r, j) - pureTorque;
  double linear = 0;
  double quadratic = 0;
  addBodyTerms<d>(a, j, jTauA, linear, quadratic);
  addBodyTerms<d>(b, Vec<d>(-j), jTauB, linear, quadratic);

  ClampResult result;
  if (!(quadratic > 0)) {
    // Neither body can change its energy (both infinite or a zero impulse).
    result.energyChange = linear;
    return result;
  }
  // KE' - KE = 0 at s = 0 and at the thesis's epsilon = -2 linear / quadratic.
  const double epsilon = -2 * linear / quadratic;
  if (epsilon >= 1) {
    result.scale = 1;  // friction or restitution < 1 removes energy: keep the impulse
    result.kind = ClampResult::Case::NoGain;
  } else if (epsilon > 0) {
    result.scale = epsilon;  // the impulse would add energy: shrink it to the energy-neutral one
    result.kind = ClampResult::Case::Scaled;
  } else {
    // Every small multiple adds energy: an infeasible direction of the split state; discard.
    result.scale = 0;
    result.kind = ClampResult::Case::Discarded;
  }
  result.energyChange = result.scale * linear + 0.5 * result.scale * result.scale * quadratic;
  return result;
}

template ClampResult clampImpulseEnergy<2>(const ClampBody<2>&, const ClampBody<2>&, const Vec<2>&,
                                           const AngVec<2>&);
template ClampResult clampImpulseEnergy<3>(const ClampBody<3>&, const ClampBody<3>&, const Vec<3>&,
                                           const AngVec<3>&);

}  // namespace monolith::solvers::contact

#pragma once
// Energy clamping of an impulse, thesis Sec. 2.3.2. An impulse j at r_A on A (and -j at r_B on B)
// is scaled by epsilon in [0, 1] so that the kinetic energy of the *non-split* reference state
// cannot rise: collisions clamp against (x^n, v^n), the second contact step against
// (x^{n+1}, v^{n+1}); the first contact step is never clamped. The impulse itself and the lever
// arms come from the split state. For a kinematic partner the caller passes the dynamic body's
// velocity relative to the kinematic body's point velocity (energy in its moving frame) and
// infinite mass for the kinematic body.
#include "solvers/contact/rigid_math.h"

namespace monolith::solvers::contact {

template <int d>
struct ClampBody {
  double inverseMass = 0;                         // 0: infinite mass (its terms vanish)
  AngMat<d> inverseInertia = AngMat<d>::Zero();   // world, at the reference state's rotation
  Vec<d> velocity = Vec<d>::Zero();               // reference state (p = m v)
  AngVec<d> angularMomentum = AngVec<d>::Zero();  // reference state L
  Vec<d> r = Vec<d>::Zero();                      // lever arm of the impulse (split state)
};

struct ClampResult {
  double scale = 1;         // epsilon applied to the impulse, in [0, 1]
  double energyChange = 0;  // KE' - KE of the reference state after the scaled impulse (<= ~0)
  enum class Case { NoGain, Scaled, Discarded } kind = Case::NoGain;
};

// Linear and angular impulse on A: j and j_tau = r_A x j (+ optional pure torque jTau); on B:
// -j and -(r_B x j) - jTau. Cases of the thesis's epsilon = -2 (linear) / (quadratic): no
// quadratic term or epsilon >= 1 -> NoGain (scale 1); 0 < epsilon < 1 -> Scaled;
// epsilon <= 0 (energy rises for every small scale) -> Discarded (scale 0).
template <int d>
ClampResult clampImpulseEnergy(const ClampBody<d>& a, const ClampBody<d>& b, const Vec<d>& j,
                               const AngVec<d>& pureTorque = AngVec<d>::Zero());

}  // namespace monolith::solvers::contact

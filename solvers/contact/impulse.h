#pragma once
// Impulses between two rigid bodies at one point (thesis Sec. 2.3, 4.4-4.5; Guendelman, Bridson
// & Fedkiw 2003). Conventions (notes 7.2): the relative velocity is v_A - v_B at the point, the
// unit normal points out of B towards A, A receives +j and B receives -j, and the pair is
// approaching when v_rel . n < 0. A body of infinite mass (static, kinematic, or frozen by shock
// propagation) has inverseMass = 0 and inverseInertia = 0.
#include "solvers/contact/rigid_math.h"

namespace monolith::solvers::contact {

// What an impulse needs to know of one body at the contact.
template <int d>
struct ImpulseBody {
  double inverseMass = 0;
  AngMat<d> inverseInertia = AngMat<d>::Zero();  // world frame
  Vec<d> r = Vec<d>::Zero();                     // centre of mass -> contact point
};

// K = m^{-1} delta + r*^T I^{-1} r*: the velocity change at the point per unit impulse there.
template <int d>
Mat<d> impulseFactor(const ImpulseBody<d>& body);

struct ImpulseSettings {
  double restitution = 0;  // e; contact uses e = -1 + epsilon (notes 1.6)
  double friction = 0;     // Coulomb mu
  // Rescale the new tangential relative speed to at most the old one (collisions, e != 0).
  bool clampFrictionMagnitude = false;
};

// The impulse j on A (-j on B) that makes the normal relative velocity -e min(0, v_rel.n) with
// Coulomb friction: the sticking impulse if it lies in the friction cone, else the sliding one
// (velocity change along K(n - mu t) scaled to the target normal velocity), as in notes 1.5.
// K = K_A + K_B must be invertible (at least one body finite). A pair that is not approaching
// (v_rel.n >= 0) gets zero. Where no sliding impulse reaches the target normal velocity
// (n.K(n - mu t) <= 0, friction coupled through K pulling the bodies together) the impulse is
// the frictionless one. Restitution may be negative (contact's -1 + eps).
template <int d>
Vec<d> pointImpulse(const Mat<d>& K, const Vec<d>& relativeVelocity, const Vec<d>& normal,
                    const ImpulseSettings& s);

}  // namespace monolith::solvers::contact

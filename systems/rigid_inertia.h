#pragma once
// A 3-D rigid body's inertia as the orientation update of Sec. 2.2 / App. A takes it (what
// advance_rigid_positions uses, and what pre-stabilization predicts it will do).
#include "components/rigid_body.h"
#include "solvers/rigid_rotation.h"

namespace monolith {

inline solvers::BodyInertia bodyInertia(const RigidBody<3>& b) {
  solvers::BodyInertia I;
  I.I0 = b.inertiaBody;
  I.I0inv = b.inertiaBodyInverse;
  I.principalMoments = b.principalMoments;
  I.principalAxes = b.principalAxes;
  return I;
}

}  // namespace monolith

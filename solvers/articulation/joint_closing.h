#pragma once
// Closing the joints after interpenetration resolution without pushing bodies back into what
// they touch (not in the thesis). Push-out (App. B) moves bodies one contact at a time and pulls
// joints apart; closing them by the least mass-weighted displacement alone (closeJoints) moved
// jointed bodies back into their contacts, which the next step's contact only stops from
// approaching further, so push-out separated them again: a cycle that kept a ragdoll pile
// stirring. Here the contacts around the jointed bodies are temporary normal-only rows on the
// same displacements (Sec. 4.7.1's contacts as joints, at the position level): the separation a
// point gains along its normal is at least a given amount.
#include <vector>

#include "solvers/articulation/joint_constraints.h"

namespace monolith::solvers {

// One contact point between bodies a and b (indices into the body list; an immovable partner may
// be any body of zero inverse mass, such as the world at 0).
struct ContactRow {
  int a = 0, b = 0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();  // unit, out of b towards a
  double gain = 0;  // the least separation the displacements must add along the normal (< 0: may approach)
  double friction = 0;  // Coulomb coefficient: the point's tangential slip is held while |t| <= friction n
  // Rolling resistance (a length): the bodies' relative turn about the tangent plane's axes is
  // held while that angular impulse stays within rolling x the normal impulse (the normal force
  // acting that far ahead of the contact point). 0: free rolling.
  double rolling = 0;
  // The motion of a relative to b at the point that the bodies' own moves leave out (a partner
  // held still in the solve but moving: its velocity at the point, with the sign of its side).
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
};

// Displaces the bodies (x + dx, exp(dtheta*) q) so that the joints close: `sweeps` sweeps of
// one Newton step per joint (pre-stabilization's, with dt = 1) followed by projected
// Gauss-Seidel on the contact rows (mass-weighted, impulses >= 0, rows linearised at the
// current poses; two tangential rows per point hold its slip within the friction cone of its
// normal impulse, since a frictionless position solve lets a resting pile creep sideways by
// millimetres per step), then closeJoints for what the joints still miss. Velocities are untouched.
// Returns the joint errors before and after.
PreStabilizationReport closeJointsAgainstContacts(const std::vector<JointDefinition>& joints,
                                                  std::vector<ConstraintBody>& bodies,
                                                  const std::vector<ContactRow>& contacts, int sweeps, bool global,
                                                  int maxIterations, double tolerance);

// Step V (Sec. 4.7.1, 4.7.3: contacts as temporary joints in the constrained solve): the
// velocities projected onto the joints and the contacts together, by projected Gauss-Seidel;
// each sweep goes over the contact rows (normal >= gain, friction in the cone, rolling resistance
// in its disc), then once over
// the joints (projectPairwise, the rows set to zero). The impulses' torques are added to the
// bodies' angularImpulse. Returns the sweeps and the joints' residual after the last one.
ProjectionReport projectWithContacts(const std::vector<JointRows>& joints, const std::vector<ContactRow>& contacts,
                                     std::vector<ConstraintBody>& bodies, int sweeps, double tolerance);

}  // namespace monolith::solvers

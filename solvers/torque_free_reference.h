// Converged reference solution for a torque-free rigid body, used to measure the accuracy of the
// orientation updates of Sec. 4.4.1 / Appendix A. It integrates a different formulation than the
// schemes under test (Euler's equations for the body-frame momentum plus the quaternion kinematics,
// classical RK4 with many substeps) so that agreement is evidence, not a tautology.
#pragma once

#include "solvers/rigid_rotation.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace monolith::solvers {

struct TorqueFreeState {
  Eigen::Quaterniond q;  // body-to-world orientation
  Eigen::Vector3d L;     // world angular momentum (constant in exact arithmetic)
};

// Advances the state by time T with `substeps` RK4 steps. The world L of the result is recomputed
// from the integrated body-frame momentum, so its drift measures the reference's own error.
// Throws std::invalid_argument if substeps < 1 or T is not finite.
TorqueFreeState advanceTorqueFreeReference(const BodyInertia& inertia, const TorqueFreeState& start,
                                           double T, int substeps);

// Orientation at time T starting from q0 with world angular momentum Lworld.
Eigen::Quaterniond torqueFreeReferenceOrientation(const BodyInertia& inertia,
                                                  const Eigen::Quaterniond& q0,
                                                  const Eigen::Vector3d& Lworld, double T,
                                                  int substeps);

// Body-frame angular velocity I0^-1 R^T L.
Eigen::Vector3d bodyAngularVelocity(const BodyInertia& inertia, const Eigen::Quaterniond& q,
                                    const Eigen::Vector3d& Lworld);

// Angle of the rotation a^-1 b, in [0, pi]; insensitive to the quaternion sign (q and -q are the
// same orientation).
double rotationAngleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b);

}  // namespace monolith::solvers

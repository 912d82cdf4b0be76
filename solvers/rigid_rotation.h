// Rigid-body orientation evolution with angular momentum held fixed, and the kinetic-energy
// orientation fix of the thesis (Schroeder 2011), Sections 2.2, 4.4.1 and Appendix A.
//
// Conventions (used throughout): R is the body-to-world rotation of the unit quaternion q,
// the world inertia is I = R I0 R^T, the world angular momentum L is the primary state and the
// world angular velocity is derived from it, w = I^-1 L. a* denotes the cross-product matrix of
// a (a* b = a x b). Orientation updates are applied on the left, R <- exp(u*) R (Sec. 4.4.1).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace monolith::solvers {

// Accuracy of the orientation update of Sec. 4.4.1 / Appendix A (local error O(dt^(order+1))).
enum class RotationOrder { First = 1, Second = 2, Third = 3 };

// a* such that a* b == a x b (the thesis' "*" notation, Sec. 2.2.1).
Eigen::Matrix3d crossMatrix(const Eigen::Vector3d& a);

// exp(u*) as a unit quaternion: rotation by |u| about u/|u|. Uses a Taylor series for
// sin(|u|/2)/|u| near zero so that tiny rotation vectors (and u = 0) stay exact to rounding.
Eigen::Quaterniond rotationExponential(const Eigen::Vector3d& u);

// Body-frame inertia of one rigid body, precomputed once (the eigen-decomposition is needed by
// the principal-axis fallback of Sec. 2.2.4 and must not be recomputed every step).
struct BodyInertia {
  Eigen::Matrix3d I0;                 // symmetric positive definite, body frame
  Eigen::Matrix3d I0inv;              // its inverse (symmetric)
  Eigen::Vector3d principalMoments;   // ascending
  Eigen::Matrix3d principalAxes;      // columns (body frame) matching principalMoments; det = +1

  // Throws std::invalid_argument if I0 is not finite, not symmetric (to a relative 1e-10) or not
  // numerically positive definite.
  static BodyInertia fromMatrix(const Eigen::Matrix3d& I0);
};

// World inverse inertia R I0^-1 R^T.
Eigen::Matrix3d worldInverseInertia(const BodyInertia& inertia, const Eigen::Quaterniond& q);

// Rotational kinetic energy 1/2 L^T I^-1(q) L (Sec. 2.2.1).
double rotationalKineticEnergy(const BodyInertia& inertia, const Eigen::Quaterniond& q,
                               const Eigen::Vector3d& L);

// Full rotation vector u of one step of length dt with world angular momentum L held fixed
// (torque free), w = I^-1(q) L. The step is R <- exp(u*) R: Sec. 4.4.1 prints exp(dt u*) with a u
// that already contains dt, but App. A's derivation (R^{n+1} R^T = exp(dt u1* + dt^2 u2* + ...))
// and the convergence tests show the exponent is u itself.
//   First : u = dt w                                                    ([169], Sec. 4.4.1)
//   Second: u = dt w + dt^2/2 I^-1 (L x w)                              (Sec. 4.4.1, App. A)
//   Third : u = Second + dt^3 u3,
//           u3 = 1/12 w* I^-1 L* w - 1/6 I^-1 w* L* w + 1/6 I^-1 L* I^-1 L* w   (App. A)
Eigen::Vector3d rotationIncrement(RotationOrder order, double dt, const BodyInertia& inertia,
                                  const Eigen::Quaterniond& q, const Eigen::Vector3d& L);

// One orientation step: q <- normalize(exp(u*) q) with u = rotationIncrement(...).
Eigen::Quaterniond advanceOrientation(RotationOrder order, double dt, const BodyInertia& inertia,
                                      const Eigen::Quaterniond& q, const Eigen::Vector3d& L);

struct EnergyFixReport {
  enum class Status {
    WithinTolerance,    // |KE - KE0| <= 4 eps KE0 on entry: nothing to correct
    NegligibleEnergy,   // KE0 < eps^2 or L = 0: the energy is irrelevant, q untouched
    Fixed,              // corrected along the locally optimal axis s = L x w (Sec. 2.2.2-2.2.3)
    FixedWithFallback,  // corrected using principal-axis fallback directions (Sec. 2.2.4)
    ResidualAccepted    // KE0 not reachable (or retry cap hit): left at the best energy found
  };
  Status status = Status::WithinTolerance;
  int fallbackRotations = 0;        // rotations applied along principal-axis fallback directions
  double relativeErrorBefore = 0;   // (KE - KE0)/KE0 on entry (0 when KE0 == 0)
  double relativeErrorAfter = 0;    // (KE - KE0)/KE0 on exit
};

// Sec. 2.2.2-2.2.4: rotate q about world axes s perpendicular to L (L is fixed in the world, so
// angular momentum stays exact) until 1/2 L^T I^-1(q) L == KE0. Never aborts: if KE0 lies outside
// the energies reachable with this |L| the body is left at the extremum and the residual reported.
// q must be a unit quaternion on entry; it is left untouched unless a rotation is applied.
// Throws std::invalid_argument if KE0 is negative or not finite.
EnergyFixReport correctOrientationForKineticEnergy(Eigen::Quaterniond& q, const BodyInertia& inertia,
                                                   const Eigen::Vector3d& L, double KE0);

}  // namespace monolith::solvers

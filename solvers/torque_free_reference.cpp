#include "solvers/torque_free_reference.h"

#include <cmath>
#include <stdexcept>

namespace monolith::solvers {

namespace {

// ODE state: quaternion coefficients (Eigen order x, y, z, w) and body-frame angular momentum.
struct OdeState {
  Eigen::Vector4d q;
  Eigen::Vector3d Lb;
};

OdeState axpy(const OdeState& x, double h, const OdeState& dx) {
  return {x.q + h * dx.q, x.Lb + h * dx.Lb};
}

// Torque-free rigid body in the body frame:
//   Euler's equations  d(Lb)/dt = Lb x wb,  wb = I0^-1 Lb   (world L constant <=> Lb' = -wb x Lb)
//   kinematics         dq/dt = 1/2 q (0, wb)                (body-frame angular velocity)
OdeState derivative(const BodyInertia& inertia, const OdeState& x) {
  const Eigen::Vector3d wb = inertia.I0inv * x.Lb;
  const Eigen::Quaterniond q(x.q);  // Eigen's Vector4 constructor takes (x, y, z, w)
  const Eigen::Quaterniond omega(0.0, wb.x(), wb.y(), wb.z());
  return {0.5 * (q * omega).coeffs(), x.Lb.cross(wb)};
}

OdeState rk4Step(const BodyInertia& inertia, const OdeState& x, double h) {
  const OdeState k1 = derivative(inertia, x);
  const OdeState k2 = derivative(inertia, axpy(x, 0.5 * h, k1));
  const OdeState k3 = derivative(inertia, axpy(x, 0.5 * h, k2));
  const OdeState k4 = derivative(inertia, axpy(x, h, k3));
  OdeState next{x.q + h / 6.0 * (k1.q + 2 * k2.q + 2 * k3.q + k4.q),
                x.Lb + h / 6.0 * (k1.Lb + 2 * k2.Lb + 2 * k3.Lb + k4.Lb)};
  // RK4 preserves |q| only to O(h^5); renormalising keeps q a rotation over many substeps.
  next.q.normalize();
  return next;
}

}  // namespace

TorqueFreeState advanceTorqueFreeReference(const BodyInertia& inertia, const TorqueFreeState& start,
                                           double T, int substeps) {
  if (substeps < 1 || !std::isfinite(T))
    throw std::invalid_argument("advanceTorqueFreeReference: need substeps >= 1 and finite T");
  const Eigen::Quaterniond q0 = start.q.normalized();
  OdeState x{q0.coeffs(), q0.conjugate() * start.L};
  const double h = T / substeps;
  for (int i = 0; i < substeps; ++i) x = rk4Step(inertia, x, h);
  const Eigen::Quaterniond q(x.q);
  return {q, q * x.Lb};
}

Eigen::Quaterniond torqueFreeReferenceOrientation(const BodyInertia& inertia,
                                                  const Eigen::Quaterniond& q0,
                                                  const Eigen::Vector3d& Lworld, double T,
                                                  int substeps) {
  return advanceTorqueFreeReference(inertia, {q0, Lworld}, T, substeps).q;
}

Eigen::Vector3d bodyAngularVelocity(const BodyInertia& inertia, const Eigen::Quaterniond& q,
                                    const Eigen::Vector3d& Lworld) {
  return inertia.I0inv * (q.conjugate() * Lworld);
}

double rotationAngleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  const Eigen::Quaterniond d = a.normalized().conjugate() * b.normalized();
  // atan2 stays accurate for tiny angles where acos(|w|) would lose half the digits; |w| folds
  // the double cover so the result is in [0, pi].
  return 2.0 * std::atan2(d.vec().norm(), std::abs(d.w()));
}

}  // namespace monolith::solvers

#pragma once
// RigidBody<d>: one entity per body (DESIGN.md §4). The angular state is the world-frame
// angular momentum L, as in the thesis's code: it is what collisions, contact and the energy
// fix of Sec. 2.2 keep exact; the angular velocity w = I^{-1}(R) L is always derived.
// In 2-D the angular quantities are 1-vectors (rotation about z) and the orientation is an angle.
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <type_traits>

namespace monolith {

template <int d>
using AngularVec = std::conditional_t<d == 3, Eigen::Vector3d, Eigen::Matrix<double, 1, 1>>;
template <int d>
using InertiaMat = std::conditional_t<d == 3, Eigen::Matrix3d, Eigen::Matrix<double, 1, 1>>;
template <int d>
using Orientation = std::conditional_t<d == 3, Eigen::Quaterniond, double>;

template <int d>
struct RigidBody {
  static constexpr const char* kName = "rigid_body";
  using VecD = Eigen::Matrix<double, d, 1>;
  using MatD = Eigen::Matrix<double, d, d>;

  // --- state (checkpointed) ---
  double mass = 1;
  InertiaMat<d> inertiaBody = InertiaMat<d>::Identity();  // body-frame inertia I_0
  VecD x = VecD::Zero();                                  // centre of mass
  Orientation<d> orientation = identityOrientation();     // R (unit quaternion / angle)
  VecD v = VecD::Zero();                                  // linear velocity
  AngularVec<d> L = AngularVec<d>::Zero();                // world angular momentum
  bool isStatic = false;                                  // infinite mass, never moves

  // --- derived from the state by refresh() (not checkpointed) ---
  InertiaMat<d> inertiaBodyInverse = InertiaMat<d>::Identity();
  AngularVec<d> principalMoments = AngularVec<d>::Ones();  // ascending
  InertiaMat<d> principalAxes = InertiaMat<d>::Identity();  // columns, body frame

  static Orientation<d> identityOrientation() {
    if constexpr (d == 3) return Eigen::Quaterniond::Identity();
    else return 0.0;
  }

  template <class V>
  void visitFields(V& visit) {
    visit("mass", mass);
    visit("inertia_body", inertiaBody);
    visit("position", x);
    visit("orientation", orientation);
    visit("velocity", v);
    visit("angular_momentum", L);
    visit("static", isStatic);
  }
  void afterLoad() { refresh(); }

  // Recomputes the derived inertia data; call after changing inertiaBody.
  void refresh() {
    inertiaBodyInverse = inertiaBody.inverse();
    if constexpr (d == 3) {
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(inertiaBody);
      principalMoments = eig.eigenvalues();
      principalAxes = eig.eigenvectors();
    } else {
      principalMoments = inertiaBody;
    }
  }

  MatD rotation() const {
    if constexpr (d == 3) return orientation.toRotationMatrix();
    else return Eigen::Rotation2Dd(orientation).toRotationMatrix();
  }
  // World-frame inverse inertia R I_0^{-1} R^T (rotation-invariant in 2-D).
  InertiaMat<d> worldInverseInertia() const {
    if constexpr (d == 3) {
      const Eigen::Matrix3d R = rotation();
      return R * inertiaBodyInverse * R.transpose();
    } else {
      return inertiaBodyInverse;
    }
  }
  InertiaMat<d> worldInertia() const {
    if constexpr (d == 3) {
      const Eigen::Matrix3d R = rotation();
      return R * inertiaBody * R.transpose();
    } else {
      return inertiaBody;
    }
  }
  AngularVec<d> omega() const { return worldInverseInertia() * L; }
  void setOmega(const AngularVec<d>& w) { L = worldInertia() * w; }

  double translationalKineticEnergy() const { return isStatic ? 0.0 : 0.5 * mass * v.squaredNorm(); }
  double rotationalKineticEnergy() const { return isStatic ? 0.0 : 0.5 * L.dot(omega()); }
};

}  // namespace monolith

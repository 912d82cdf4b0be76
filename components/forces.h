#pragma once
// Force-related components of rigid bodies.
#include <Eigen/Core>

#include "components/rigid_body.h"

namespace monolith {

// A constant world-frame force and torque applied to a body (scene component "external_force").
template <int d>
struct ExternalForce {
  static constexpr const char* kName = "external_force";
  Eigen::Matrix<double, d, 1> force = Eigen::Matrix<double, d, 1>::Zero();
  AngularVec<d> torque = AngularVec<d>::Zero();
  template <class V>
  void visitFields(V& visit) {
    visit("force", force);
    visit("torque", torque);
  }
};

// Accumulated force and torque on a body at the current force evaluation (internal; one per
// dynamic body). Force systems add to it; the velocity stages read it.
template <int d>
struct RigidForces {
  static constexpr const char* kName = "rigid_forces";
  Eigen::Matrix<double, d, 1> force = Eigen::Matrix<double, d, 1>::Zero();
  AngularVec<d> torque = AngularVec<d>::Zero();
  template <class V>
  void visitFields(V& visit) {
    visit("force", force);
    visit("torque", torque);
  }
};

}  // namespace monolith

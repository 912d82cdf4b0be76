#pragma once
// An elastic mount of a rigid body (scene component "spring_mount"): a linear spring and dashpot
// between the body's centre of mass and a fixed world anchor, per axis,
//   f = -k (x - anchor) - c v,
// the elastically mounted cylinder of vortex-induced vibration (a body free to move in the flow
// and pulled back to its rest place).
#include <Eigen/Core>

namespace monolith {

template <int d>
struct SpringMount {
  static constexpr const char* kName = "spring_mount";
  Eigen::Matrix<double, d, 1> anchor = Eigen::Matrix<double, d, 1>::Zero();
  Eigen::Matrix<double, d, 1> stiffness = Eigen::Matrix<double, d, 1>::Zero();  // k per axis (N/m)
  Eigen::Matrix<double, d, 1> damping = Eigen::Matrix<double, d, 1>::Zero();    // c per axis (N s/m)
  template <class V>
  void visitFields(V& visit) {
    visit("anchor", anchor);
    visit("stiffness", stiffness);
    visit("damping", damping);
  }
};

}  // namespace monolith

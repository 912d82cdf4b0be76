#pragma once
// KinematicMotion<d>: a rigid body moved by a script from the scene file instead of by forces
// (the elevator platform of Sec. 2.3.2). It has infinite mass for collisions and contact, and
// its velocity is piecewise constant: segment k applies on [until_{k-1}, until_k), the last
// segment forever after.
#include <Eigen/Core>
#include <vector>

#include "components/rigid_body.h"

namespace monolith {

template <int d>
struct KinematicMotion {
  static constexpr const char* kName = "kinematic";
  static constexpr int kAngular = d == 3 ? 3 : 1;
  // Per segment: until, then d linear and kAngular angular velocity numbers.
  std::vector<double> segments;

  template <class V>
  void visitFields(V& visit) {
    visit("segments", segments);
  }

  static constexpr int stride() { return 1 + d + kAngular; }
  int segmentCount() const { return static_cast<int>(segments.size()) / stride(); }
  // Velocity and angular velocity at time t.
  void velocityAt(double t, Eigen::Matrix<double, d, 1>& v, AngularVec<d>& w) const {
    int k = 0;
    while (k + 1 < segmentCount() && t >= segments[k * stride()]) ++k;
    const double* s = segments.data() + k * stride();
    for (int i = 0; i < d; ++i) v(i) = s[1 + i];
    for (int i = 0; i < kAngular; ++i) w(i) = s[1 + d + i];
  }
};

}  // namespace monolith

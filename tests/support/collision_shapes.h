#pragma once
// Collision geometries of the narrow-phase and swept-contact unit tests, by their sizes: boxes by
// half extents, spheres and disks by radius, capsules and cylinders by radius and half height
// (axis z), half-spaces by normal and offset; and 3-D poses.
#include <Eigen/Core>

#include "solvers/collision/geometry.h"

namespace monolith::test {

inline solvers::collision::Geometry<3> box3(double hx, double hy, double hz) {
  solvers::collision::Geometry<3> g;
  g.type = solvers::collision::GeometryType::Box;
  g.halfExtents = Eigen::Vector3d(hx, hy, hz);
  return g;
}
// A sphere in 3-D, a disk in 2-D.
template <int d>
solvers::collision::Geometry<d> ball(double r) {
  solvers::collision::Geometry<d> g;
  g.type = solvers::collision::GeometryType::Sphere;
  g.radius = r;
  return g;
}
inline solvers::collision::Geometry<3> sphere3(double r) { return ball<3>(r); }
inline solvers::collision::Geometry<3> capsule3(double r, double h) {
  solvers::collision::Geometry<3> g;
  g.type = solvers::collision::GeometryType::Capsule;
  g.radius = r;
  g.halfHeight = h;
  return g;
}
inline solvers::collision::Geometry<3> cylinder3(double r, double h) {
  solvers::collision::Geometry<3> g = capsule3(r, h);
  g.type = solvers::collision::GeometryType::Cylinder;
  return g;
}
template <int d>
solvers::collision::Geometry<d> halfSpace(const Eigen::Matrix<double, d, 1>& n, double offset) {
  solvers::collision::Geometry<d> g;
  g.type = solvers::collision::GeometryType::HalfSpace;
  g.normal = n;
  g.offset = offset;
  return g;
}
inline solvers::collision::Geometry<2> box2(double hx, double hy) {
  solvers::collision::Geometry<2> g;
  g.type = solvers::collision::GeometryType::Box;
  g.halfExtents = Eigen::Vector2d(hx, hy);
  return g;
}
inline solvers::collision::Geometry<2> disk(double r) { return ball<2>(r); }

// A 3-D pose: the body frame's origin at x, turned by R.
inline solvers::collision::Pose<3> at(const Eigen::Vector3d& x, const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity()) {
  solvers::collision::Pose<3> p;
  p.x = x;
  p.R = R;
  return p;
}

}  // namespace monolith::test

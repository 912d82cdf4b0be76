#include "solvers/collision/face_escape.h"

#include <limits>
#include <stdexcept>

#include "solvers/collision/contact_axis_impl.h"

namespace monolith::solvers::collision {

namespace {

// The point of the posed, bounded shape lowest along the unit direction n.
Eigen::Vector3d lowestAlong(const PreparedGeometry<3>& g, const Pose<3>& pose, const Eigen::Vector3d& n) {
  return supportPoint(g, pose, -n);
}

Eigen::Vector2d lowestAlong(const PreparedGeometry<2>& g, const Pose<2>& pose, const Eigen::Vector2d& n) {
  if (g.geometry().type == GeometryType::Sphere) return pose.x - g.geometry().radius * n;
  // Box and polygon: their vertices (the hull, counter-clockwise, body frame).
  Eigen::Vector2d best = pose.x;
  double lowest = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector2d& v : g.impl().vertices) {
    const Eigen::Vector2d p = pose.R * v + pose.x;
    if (n.dot(p) < lowest) lowest = n.dot(p), best = p;
  }
  return best;
}

}  // namespace

template <int d>
bool escapeThroughBoxFace(const PreparedGeometry<d>& box, const Pose<d>& boxPose, const PreparedGeometry<d>& body,
                          const Pose<d>& bodyPose, const std::vector<Eigen::Matrix<double, d, 1>>& avoid,
                          ContactPoint<d>& out) {
  using VecD = Eigen::Matrix<double, d, 1>;
  if (box.geometry().type != GeometryType::Box) throw std::invalid_argument("escapeThroughBoxFace: not a box");
  if (body.unbounded()) return false;
  double best = std::numeric_limits<double>::infinity();
  VecD bestNormal = VecD::Zero(), bestPoint = VecD::Zero();
  for (int axis = 0; axis < d; ++axis) {
    for (double sign : {1.0, -1.0}) {
      const VecD n = sign * boxPose.R.col(axis);
      bool allowed = true;
      for (const VecD& u : avoid) allowed = allowed && n.dot(u) >= -0.5;
      if (!allowed) continue;
      const double face = n.dot(boxPose.x) + box.geometry().halfExtents[axis];
      const VecD lowest = lowestAlong(body, bodyPose, n);
      const double push = face - n.dot(lowest);
      if (push < best) best = push, bestNormal = n, bestPoint = lowest;
    }
  }
  if (!(best > 0) || best == std::numeric_limits<double>::infinity()) return false;
  out.normal = -bestNormal;
  out.depth = best;
  out.point = bestPoint + 0.5 * best * bestNormal;
  return true;
}

template bool escapeThroughBoxFace<2>(const PreparedGeometry<2>&, const Pose<2>&, const PreparedGeometry<2>&,
                                      const Pose<2>&, const std::vector<Eigen::Vector2d>&, ContactPoint<2>&);
template bool escapeThroughBoxFace<3>(const PreparedGeometry<3>&, const Pose<3>&, const PreparedGeometry<3>&,
                                      const Pose<3>&, const std::vector<Eigen::Vector3d>&, ContactPoint<3>&);

}  // namespace monolith::solvers::collision

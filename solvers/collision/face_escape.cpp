#include "solvers/collision/face_escape.h"

#include <limits>
#include <stdexcept>

#include "solvers/collision/contact_axis_impl.h"

namespace monolith::solvers::collision {

bool escapeThroughBoxFace(const PreparedGeometry<3>& box, const Pose<3>& boxPose, const PreparedGeometry<3>& body,
                          const Pose<3>& bodyPose, const std::vector<Eigen::Vector3d>& avoid, ContactPoint<3>& out) {
  if (box.geometry().type != GeometryType::Box) throw std::invalid_argument("escapeThroughBoxFace: not a box");
  if (body.unbounded()) return false;
  double best = std::numeric_limits<double>::infinity();
  Eigen::Vector3d bestNormal = Eigen::Vector3d::Zero();
  for (int axis = 0; axis < 3; ++axis) {
    for (double sign : {1.0, -1.0}) {
      const Eigen::Vector3d n = sign * boxPose.R.col(axis);
      bool allowed = true;
      for (const Eigen::Vector3d& u : avoid) allowed = allowed && n.dot(u) >= -0.5;
      if (!allowed) continue;
      const double face = n.dot(boxPose.x) + box.geometry().halfExtents[axis];
      const double push = face - projection(body, bodyPose, n, -1)[0];
      if (push < best) best = push, bestNormal = n;
    }
  }
  if (!(best > 0) || best == std::numeric_limits<double>::infinity()) return false;
  const Eigen::Vector3d deepest = supportPoint(body, bodyPose, -bestNormal);
  out.normal = -bestNormal;
  out.depth = best;
  out.point = deepest + 0.5 * best * bestNormal;
  return true;
}

}  // namespace monolith::solvers::collision

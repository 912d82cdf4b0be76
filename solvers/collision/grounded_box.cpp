#include "solvers/collision/grounded_box.h"

#include <cmath>

namespace monolith::solvers::collision {

template <int d>
Eigen::Matrix<double, d, 1> extendBoxThroughGround(Geometry<d>& box, const Pose<d>& pose,
                                                   const std::vector<HalfSpaceInWorld<d>>& grounds, double tolerance) {
  using VecD = Eigen::Matrix<double, d, 1>;
  VecD shift = VecD::Zero();
  if (box.type != GeometryType::Box) return shift;
  const double reach = 2 * box.halfExtents.maxCoeff();  // before any extension: the box's own size
  Eigen::Matrix<bool, d, 1> extended = Eigen::Matrix<bool, d, 1>::Constant(false);
  for (const HalfSpaceInWorld<d>& ground : grounds) {
    const double height = ground.normal.dot(pose.x - ground.point);  // of the centre
    if (!(height > 0)) continue;
    for (int i = 0; i < d; ++i) {
      const double along = pose.R.col(i).dot(ground.normal);  // body axis i against the normal
      if (std::abs(along) < 1 - 1e-9 || extended(i)) continue;
      const double sign = along > 0 ? 1.0 : -1.0;
      // The face whose outward normal points into the ground (body coordinate -sign h_i), and
      // how far above the plane it lies.
      const double h = box.halfExtents(i);
      if (height - h > tolerance) continue;
      box.halfExtents(i) = h + 0.5 * reach;
      shift(i) = -sign * 0.5 * reach;
      extended(i) = true;
    }
  }
  return shift;
}

template Eigen::Vector2d extendBoxThroughGround<2>(Geometry<2>&, const Pose<2>&, const std::vector<HalfSpaceInWorld<2>>&,
                                                  double);
template Eigen::Vector3d extendBoxThroughGround<3>(Geometry<3>&, const Pose<3>&, const std::vector<HalfSpaceInWorld<3>>&,
                                                  double);

}  // namespace monolith::solvers::collision

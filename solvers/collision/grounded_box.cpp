#include "solvers/collision/grounded_box.h"

#include <algorithm>
#include <cmath>

namespace monolith::solvers::collision {

namespace {

constexpr double kParallel = 1 - 1e-9;  // cosine: a face parallel to the plane or the support's face

// Whether the face of `box` (half extents h, at pose) whose outward normal is -sign * axis i
// lies, in its extent, inside face j of `support` (within tolerance), the face's plane aside.
template <int d>
bool footprintInside(const Eigen::Matrix<double, d, 1>& h, const Pose<d>& pose, int i, double sign,
                     const BoxInWorld<d>& support, int j, double tolerance) {
  using VecD = Eigen::Matrix<double, d, 1>;
  const VecD faceCentre = pose.x - sign * h(i) * pose.R.col(i);
  for (int corner = 0; corner < (1 << d); ++corner) {
    if (corner & (1 << i)) continue;  // the face's corners: every sign combination but along i
    VecD p = faceCentre;
    for (int k = 0; k < d; ++k)
      if (k != i) p += ((corner & (1 << k)) ? 1.0 : -1.0) * h(k) * pose.R.col(k);
    const VecD local = support.pose.R.transpose() * (p - support.pose.x);
    for (int m = 0; m < d; ++m)
      if (m != j && std::abs(local(m)) > support.halfExtents(m) + tolerance) return false;
  }
  return true;
}

}  // namespace

template <int d>
Eigen::Matrix<double, d, 1> extendBoxThroughGround(Geometry<d>& box, const Pose<d>& pose,
                                                   const std::vector<HalfSpaceInWorld<d>>& grounds, double tolerance,
                                                   const std::vector<BoxInWorld<d>>& supports) {
  using VecD = Eigen::Matrix<double, d, 1>;
  VecD shift = VecD::Zero();
  if (box.type != GeometryType::Box) return shift;
  const VecD given = box.halfExtents;
  const double reach = 2 * given.maxCoeff();  // before any extension: the box's own size
  Eigen::Matrix<bool, d, 1> extended = Eigen::Matrix<bool, d, 1>::Constant(false);
  // Body axis i reaches `length` further out of the face at -sign h_i; the opposite face stays.
  auto extend = [&](int i, double sign, double length) {
    box.halfExtents(i) = given(i) + 0.5 * length;
    shift(i) = -sign * 0.5 * length;
    extended(i) = true;
  };
  for (const HalfSpaceInWorld<d>& ground : grounds) {
    const double height = ground.normal.dot(pose.x - ground.point);  // of the centre
    if (!(height > 0)) continue;
    for (int i = 0; i < d; ++i) {
      const double along = pose.R.col(i).dot(ground.normal);  // body axis i against the normal
      if (std::abs(along) < kParallel || extended(i)) continue;
      const double sign = along > 0 ? 1.0 : -1.0;
      // The face whose outward normal points into the ground (body coordinate -sign h_i), and
      // how far above the plane it lies.
      if (height - given(i) > tolerance) continue;
      extend(i, sign, reach);
    }
  }
  const double radius = given.norm();
  for (const BoxInWorld<d>& support : supports) {
    const VecD offset = pose.x - support.pose.x;
    if (offset.norm() > radius + support.halfExtents.norm() + tolerance) continue;  // cannot touch
    for (int j = 0; j < d; ++j) {
      // The support's face on the side of the box's centre, and the centre's height above it.
      const VecD n = support.pose.R.col(j).dot(offset) >= 0 ? VecD(support.pose.R.col(j)) : VecD(-support.pose.R.col(j));
      const double height = n.dot(offset) - support.halfExtents(j);
      if (!(height > 0)) continue;
      for (int i = 0; i < d; ++i) {
        const double along = pose.R.col(i).dot(n);
        if (std::abs(along) < kParallel || extended(i)) continue;
        const double sign = along > 0 ? 1.0 : -1.0;
        const double bottom = height - given(i);  // the box's face towards the support, above its face
        if (bottom > tolerance) continue;
        if (!footprintInside<d>(given, pose, i, sign, support, j, tolerance)) continue;
        // Down to the support's far face at most: the extension stays inside the support.
        const double length = std::min(reach, bottom + 2 * support.halfExtents(j));
        if (length > 0) extend(i, sign, length);
      }
    }
  }
  return shift;
}

template Eigen::Vector2d extendBoxThroughGround<2>(Geometry<2>&, const Pose<2>&, const std::vector<HalfSpaceInWorld<2>>&,
                                                  double, const std::vector<BoxInWorld<2>>&);
template Eigen::Vector3d extendBoxThroughGround<3>(Geometry<3>&, const Pose<3>&, const std::vector<HalfSpaceInWorld<3>>&,
                                                  double, const std::vector<BoxInWorld<3>>&);

}  // namespace monolith::solvers::collision

#pragma once
// Shape<d>: the geometry of a body, used for its inertia (when the scene gives none), for the
// geometry frames written for ParaView, and (from the collision issue on) for colliders.
#include <Eigen/Core>
#include <string>

namespace monolith {

enum class ShapeType : int { Box = 0, Sphere = 1 };  // 2-D: box and disk (a "sphere" in 2-D)

template <int d>
struct Shape {
  static constexpr const char* kName = "shape";
  using VecD = Eigen::Matrix<double, d, 1>;

  ShapeType type = ShapeType::Box;
  VecD halfExtents = VecD::Constant(0.5);  // box
  double radius = 0.5;                     // sphere / disk

  template <class V>
  void visitFields(V& visit) {
    int t = static_cast<int>(type);
    visit("type", t);
    type = static_cast<ShapeType>(t);
    visit("half_extents", halfExtents);
    visit("radius", radius);
  }

  // Body-frame inertia of a solid of this shape with the given mass (principal axes = body axes).
  Eigen::Matrix<double, d == 3 ? 3 : 1, d == 3 ? 3 : 1> inertia(double mass) const {
    if constexpr (d == 3) {
      Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
      if (type == ShapeType::Box) {
        const Eigen::Vector3d e2 = (2 * halfExtents).cwiseAbs2();  // full edge lengths squared
        I.diagonal() << mass / 12 * (e2.y() + e2.z()), mass / 12 * (e2.x() + e2.z()), mass / 12 * (e2.x() + e2.y());
      } else {
        I.diagonal().setConstant(0.4 * mass * radius * radius);
      }
      return I;
    } else {
      Eigen::Matrix<double, 1, 1> I;
      if (type == ShapeType::Box) I(0) = mass / 12 * (2 * halfExtents).squaredNorm();
      else I(0) = 0.5 * mass * radius * radius;
      return I;
    }
  }
};

}  // namespace monolith

#pragma once
// Shape<d>: the geometry of a body, used for its inertia (when the scene gives none), for the
// geometry frames written for ParaView, and for collisions (with a `collider` component).
// 3-D: box, sphere, capsule and cylinder (axis = body z), plane (a half-space, static bodies
// only), convex hull of vertices, triangle mesh. 2-D: box, disk (type Sphere), convex polygon,
// plane (half-plane). Vertices are in the body frame, centred on the centre of mass.
#include <Eigen/Core>
#include <string>
#include <vector>

namespace monolith {

enum class ShapeType : int { Box = 0, Sphere = 1, Capsule = 2, Cylinder = 3, Plane = 4, Convex = 5, Mesh = 6 };

template <int d>
struct Shape {
  static constexpr const char* kName = "shape";
  using VecD = Eigen::Matrix<double, d, 1>;

  ShapeType type = ShapeType::Box;
  VecD halfExtents = VecD::Constant(0.5);  // box
  double radius = 0.5;                     // sphere / disk, capsule, cylinder
  double halfHeight = 0.5;                 // capsule (half segment), cylinder (half height)
  VecD normal = VecD::UnitY();             // plane: outward unit normal, body frame
  std::vector<double> vertices;            // convex / mesh: d numbers per vertex
  std::vector<int> triangles;              // mesh: 3 indices per triangle

  template <class V>
  void visitFields(V& visit) {
    int t = static_cast<int>(type);
    visit("type", t);
    type = static_cast<ShapeType>(t);
    visit("half_extents", halfExtents);
    visit("radius", radius);
    visit("half_height", halfHeight);
    visit("normal", normal);
    visit("vertices", vertices);
    visit("triangles", triangles);
  }

  int vertexCount() const { return static_cast<int>(vertices.size()) / d; }
  VecD vertex(int i) const { return Eigen::Map<const VecD>(vertices.data() + d * i); }

  // Body-frame inertia of a solid of this shape with the given mass (principal axes = body
  // axes). Convex hulls in 3-D and meshes have no closed form here: the scene must give an
  // inertia (checked when the scene is read). A 2-D convex polygon uses its exact area moment.
  Eigen::Matrix<double, d == 3 ? 3 : 1, d == 3 ? 3 : 1> inertia(double mass) const {
    if constexpr (d == 3) {
      Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
      const double r2 = radius * radius;
      if (type == ShapeType::Box) {
        const Eigen::Vector3d e2 = (2 * halfExtents).cwiseAbs2();  // full edge lengths squared
        I.diagonal() << mass / 12 * (e2.y() + e2.z()), mass / 12 * (e2.x() + e2.z()), mass / 12 * (e2.x() + e2.y());
      } else if (type == ShapeType::Cylinder) {
        const double h2 = 4 * halfHeight * halfHeight;
        const double side = mass * (3 * r2 + h2) / 12;
        I.diagonal() << side, side, 0.5 * mass * r2;
      } else if (type == ShapeType::Capsule) {
        // Cylinder of half height h plus two hemispheres (solid of uniform density).
        const double h = halfHeight;
        const double vc = M_PI * r2 * 2 * h, vs = 4.0 / 3.0 * M_PI * r2 * radius;
        const double mc = mass * vc / (vc + vs), ms = mass - mc;
        const double axial = 0.5 * mc * r2 + 0.4 * ms * r2;
        const double side = mc * (3 * r2 + 4 * h * h) / 12 + ms * (0.4 * r2 + h * h + 0.75 * h * radius);
        I.diagonal() << side, side, axial;
      } else {
        I.diagonal().setConstant(0.4 * mass * r2);
      }
      return I;
    } else {
      Eigen::Matrix<double, 1, 1> I;
      if (type == ShapeType::Box) {
        I(0) = mass / 12 * (2 * halfExtents).squaredNorm();
      } else if (type == ShapeType::Convex) {
        // Polygon about its centroid (the origin): sum over fan triangles (shoelace form).
        double area = 0, moment = 0;
        const int n = vertexCount();
        for (int i = 0; i < n; ++i) {
          const VecD a = vertex(i), b = vertex((i + 1) % n);
          const double cross = a.x() * b.y() - a.y() * b.x();
          area += 0.5 * cross;
          moment += cross * (a.squaredNorm() + a.dot(b) + b.squaredNorm()) / 12;
        }
        I(0) = mass * moment / area;
      } else {
        I(0) = 0.5 * mass * radius * radius;
      }
      return I;
    }
  }
};

}  // namespace monolith

// Volumes of body shapes (see shape_volume.h).
#include "systems/shape_volume.h"

#include <Eigen/Geometry>

#include <cmath>

namespace monolith {

template <int d>
double shapeVolume(const Shape<d>& shape) {
  const double r = shape.radius;
  switch (shape.type) {
    case ShapeType::Sphere: return d == 2 ? M_PI * r * r : 4.0 / 3.0 * M_PI * r * r * r;
    case ShapeType::Box: return std::pow(2.0, d) * shape.halfExtents.prod();
    case ShapeType::Cylinder: return d == 3 ? M_PI * r * r * 2 * shape.halfHeight : 0.0;
    case ShapeType::Capsule: return d == 3 ? M_PI * r * r * (2 * shape.halfHeight + 4.0 / 3.0 * r) : 0.0;
    case ShapeType::Convex: {
      if constexpr (d == 2) {  // shoelace
        double area = 0;
        const int n = shape.vertexCount();
        for (int i = 0; i < n; ++i) {
          const auto a = shape.vertex(i), b = shape.vertex((i + 1) % n);
          area += 0.5 * (a.x() * b.y() - a.y() * b.x());
        }
        return std::abs(area);
      }
      return 0.0;
    }
    case ShapeType::Mesh: {
      if constexpr (d == 3) {  // divergence theorem: tetrahedra from the origin to each triangle
        double volume = 0;
        for (std::size_t t = 0; t + 2 < shape.triangles.size(); t += 3) {
          const Eigen::Vector3d a = shape.vertex(shape.triangles[t]), b = shape.vertex(shape.triangles[t + 1]),
                                c = shape.vertex(shape.triangles[t + 2]);
          volume += a.dot(b.cross(c)) / 6.0;
        }
        return std::abs(volume);
      }
      return 0.0;
    }
    case ShapeType::Plane: return 0.0;
  }
  return 0.0;
}

template double shapeVolume<2>(const Shape<2>&);
template double shapeVolume<3>(const Shape<3>&);

}  // namespace monolith

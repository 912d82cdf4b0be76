// Shape volumes for the body-volume buoyancy (systems/shape_volume.h) against closed forms: disk,
// sphere, box, polygon, cylinder, capsule, and triangle meshes (cube, prism, octahedron) in either
// orientation and away from the origin (the signed volume's sum over triangles).
#include <gtest/gtest.h>

#include <cmath>

#include "systems/shape_volume.h"

using namespace monolith;

namespace {

// A closed triangle mesh of the prism over a regular n-gon of circumradius r, height H, centred at
// `c`; outward triangles unless `inward`.
Shape<3> prismMesh(int n, double r, double H, const Eigen::Vector3d& c, bool inward) {
  Shape<3> s;
  s.type = ShapeType::Mesh;
  auto add = [&](const Eigen::Vector3d& p) {
    for (int k = 0; k < 3; ++k) s.vertices.push_back(p[k] + c[k]);
    return static_cast<int>(s.vertices.size() / 3 - 1);
  };
  auto tri = [&](int a, int b, int e) {
    if (inward) std::swap(b, e);
    s.triangles.insert(s.triangles.end(), {a, b, e});
  };
  const int bottom = add({0, 0, -H / 2}), top = add({0, 0, H / 2});
  std::vector<int> lo, hi;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    lo.push_back(add({r * std::cos(a), r * std::sin(a), -H / 2}));
    hi.push_back(add({r * std::cos(a), r * std::sin(a), H / 2}));
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    tri(bottom, lo[j], lo[i]);
    tri(top, hi[i], hi[j]);
    tri(lo[i], lo[j], hi[j]);
    tri(lo[i], hi[j], hi[i]);
  }
  return s;
}

}  // namespace

TEST(ShapeVolume, DiskSphereBoxPolygon) {
  Shape<2> disk;
  disk.type = ShapeType::Sphere;
  disk.radius = 0.3;
  EXPECT_NEAR(shapeVolume(disk), M_PI * 0.09, 1e-15);
  Shape<3> ball;
  ball.type = ShapeType::Sphere;
  ball.radius = 0.3;
  EXPECT_NEAR(shapeVolume(ball), 4.0 / 3.0 * M_PI * 0.027, 1e-15);
  Shape<3> box;
  box.halfExtents = Eigen::Vector3d(0.5, 1, 2);
  EXPECT_DOUBLE_EQ(shapeVolume(box), 8.0);
  Shape<2> triangle;  // legs 2 and 3
  triangle.type = ShapeType::Convex;
  triangle.vertices = {0, 0, 2, 0, 0, 3};
  EXPECT_DOUBLE_EQ(shapeVolume(triangle), 3.0);
  std::swap(triangle.vertices[2], triangle.vertices[4]);  // clockwise
  std::swap(triangle.vertices[3], triangle.vertices[5]);
  EXPECT_DOUBLE_EQ(shapeVolume(triangle), 3.0);
}

TEST(ShapeVolume, CylinderAndCapsule) {
  Shape<3> cylinder;
  cylinder.type = ShapeType::Cylinder;
  cylinder.radius = 0.2;
  cylinder.halfHeight = 0.7;
  EXPECT_NEAR(shapeVolume(cylinder), M_PI * 0.04 * 1.4, 1e-15);
  Shape<3> capsule = cylinder;
  capsule.type = ShapeType::Capsule;  // the cylinder plus a ball of the same radius
  EXPECT_NEAR(shapeVolume(capsule), M_PI * 0.04 * 1.4 + 4.0 / 3.0 * M_PI * 0.008, 1e-15);
  capsule.halfHeight = 0;  // a capsule without a segment is a ball
  EXPECT_NEAR(shapeVolume(capsule), 4.0 / 3.0 * M_PI * 0.008, 1e-15);
  Shape<3> plane;
  plane.type = ShapeType::Plane;
  EXPECT_EQ(shapeVolume(plane), 0.0);  // no volume: the staircase's buoyancy stays
}

TEST(ShapeVolume, MeshSignedVolumeIsExactForClosedMeshes) {
  for (bool inward : {false, true})
    for (const Eigen::Vector3d& c : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(3, -2, 5)}) {
      // Prism over a regular n-gon: (n/2) r^2 sin(2 pi / n) H.
      for (int n : {3, 4, 17}) {
        const double r = 0.4, H = 1.3;
        EXPECT_NEAR(shapeVolume(prismMesh(n, r, H, c, inward)), 0.5 * n * r * r * std::sin(2 * M_PI / n) * H, 1e-12)
            << "n " << n << " inward " << inward;
      }
      // The prism over a square of circumradius r is a box of side r sqrt(2).
      EXPECT_NEAR(shapeVolume(prismMesh(4, 1.0, 2.0, c, inward)), 2.0 * 2.0, 1e-12);
    }
  // An octahedron of "radius" a: 4/3 a^3.
  Shape<3> octa;
  octa.type = ShapeType::Mesh;
  const double a = 0.75;
  octa.vertices = {a, 0, 0, -a, 0, 0, 0, a, 0, 0, -a, 0, 0, 0, a, 0, 0, -a};
  octa.triangles = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
  EXPECT_NEAR(shapeVolume(octa), 4.0 / 3.0 * a * a * a, 1e-14);
}

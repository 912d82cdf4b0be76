// Rigid bodies against deformable faces (solvers/deformable/rigid_face_contact.h): the deepest
// point of a face in a body (sphere over a triangle's interior, a box corner poking through a
// triangle, a disk over a segment in 2-D), and impulses that stop the approach while conserving
// linear and angular momentum to round-off.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "solvers/collision/geometry.h"
#include "solvers/deformable/rigid_face_contact.h"

using namespace monolith::solvers;
using deformable::FaceContact;
using deformable::RigidFaceBody;

namespace {

template <int d>
collision::Geometry<d> sphere(double r) {
  collision::Geometry<d> g;
  g.type = collision::GeometryType::Sphere;
  g.radius = r;
  return g;
}

collision::Geometry<3> box(const Eigen::Vector3d& h) {
  collision::Geometry<3> g;
  g.type = collision::GeometryType::Box;
  g.halfExtents = h;
  return g;
}

}  // namespace

// A ball of radius 0.04 above the middle of a triangle with 0.3 m edges (its vertices 0.1 m and
// more away): the deepest point is the foot of the centre, at the plane distance minus r.
TEST(RigidFaceContact, SphereOverTriangleInteriorIsCaught) {
  const collision::PreparedGeometry<3> g(sphere<3>(0.04));
  RigidFaceBody<3> b;
  b.geometry = &g;
  b.x = Eigen::Vector3d(0.1, 0.035, 0.08);
  const Eigen::Vector3d p[3] = {{0, 0, 0}, {0.3, 0, 0}, {0, 0, 0.3}};
  const FaceContact<3> c = deformable::deepestFacePoint<3>(b, p);
  EXPECT_NEAR(c.distance, 0.035 - 0.04, 1e-15);
  EXPECT_NEAR((c.point - Eigen::Vector3d(0.1, 0, 0.08)).norm(), 0, 1e-15);
  EXPECT_NEAR(c.normal.y(), -1, 1e-15);
  EXPECT_NEAR(c.weights[0], 1 - 0.1 / 0.3 - 0.08 / 0.3, 1e-15);
  EXPECT_NEAR(c.weights[1], 0.1 / 0.3, 1e-15);
  EXPECT_NEAR(c.weights[2], 0.08 / 0.3, 1e-15);
}

// A cube turned so that one corner points down through the triangle's interior: the centre's
// foot is outside the cube, the corner seed finds the depth of the corner (to round-off).
TEST(RigidFaceContact, BoxCornerThroughTriangleFound) {
  const collision::PreparedGeometry<3> g(box(Eigen::Vector3d::Constant(0.05)));
  RigidFaceBody<3> b;
  b.geometry = &g;
  // The corner (1, 1, 1) h turned onto -y: R maps (1, 1, 1)/sqrt(3) to (0, -1, 0).
  b.R = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::Ones().normalized(), -Eigen::Vector3d::UnitY())
            .toRotationMatrix();
  const double cornerDepth = 0.004;
  b.x = Eigen::Vector3d(0.1, 0.05 * std::sqrt(3.0) - cornerDepth, 0.1);
  const Eigen::Vector3d p[3] = {{-0.2, 0, -0.2}, {0.5, 0, -0.2}, {-0.2, 0, 0.5}};
  const FaceContact<3> c = deformable::deepestFacePoint<3>(b, p);
  // The corner sits cornerDepth below the plane; the plane point under it is inside the cube by
  // the distance to the nearest of the three faces meeting there: cornerDepth / sqrt(3).
  EXPECT_NEAR(c.distance, -cornerDepth / std::sqrt(3.0), 1e-12);
  EXPECT_NEAR((c.point - Eigen::Vector3d(0.1, 0, 0.1)).norm(), 0, 1e-12);
}

// Random bodies (a dynamic box and ball) approaching random triangles of random masses (one
// particle fixed): the impulses stop every approach and keep the total linear momentum and the
// angular momentum about the origin to round-off.
TEST(RigidFaceContact, ImpulsesStopApproachAndConserveMomentum) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const collision::PreparedGeometry<3> ball(sphere<3>(0.05)), cube(box(Eigen::Vector3d(0.04, 0.06, 0.05)));
  int approaching = 0;
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<RigidFaceBody<3>> bodies(1);
    RigidFaceBody<3>& b = bodies[0];
    b.geometry = trial % 2 ? &ball : &cube;
    b.x = Eigen::Vector3d(0.01 * u(rng), (trial % 2 ? 0.055 : 0.065) + 0.005 * u(rng), 0.01 * u(rng));
    b.R = Eigen::Quaterniond(Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)).normalized()).toRotationMatrix();
    b.v = Eigen::Vector3d(u(rng), -2 + 0.5 * u(rng), u(rng));
    b.omega = 3 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    const double mass = 0.5 + 0.4 * u(rng);
    const Eigen::Matrix3d I0 = Eigen::Vector3d(2e-3, 3e-3, 4e-3).asDiagonal();
    const Eigen::Matrix3d I = b.R * I0 * b.R.transpose();
    b.inverseMass = 1 / mass;
    b.inverseInertia = I.inverse();
    b.friction = 0.4;
    const Eigen::Vector3d L0 = I * b.omega;
    std::vector<int> faces = {0, 1, 2};
    std::vector<double> x, v, w, thickness(3, 0.03), friction(3, 0.2), m(3);
    for (int i = 0; i < 3; ++i) {
      const double angle = 2 * M_PI * i / 3 + 0.3 * u(rng);
      for (double c : {0.3 * std::cos(angle), 0.005 * u(rng), 0.3 * std::sin(angle)}) x.push_back(c);
      for (int a = 0; a < 3; ++a) v.push_back(0.5 * u(rng));
      m[i] = 0.05 + 0.04 * u(rng);
      w.push_back(i == trial % 3 && trial % 5 == 0 ? 0.0 : 1 / m[i]);
    }
    auto momenta = [&](Eigen::Vector3d& P, Eigen::Vector3d& L) {
      P = mass * bodies[0].v;
      L = mass * bodies[0].x.cross(bodies[0].v) + L0 + bodies[0].angularImpulse;
      for (int i = 0; i < 3; ++i) {
        if (w[i] == 0) continue;  // fixed: outside the system
        const Eigen::Vector3d xi(x[3 * i], x[3 * i + 1], x[3 * i + 2]), vi(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
        P += m[i] * vi;
        L += m[i] * xi.cross(vi);
      }
    };
    deformable::FaceSet<3> set{&faces, &x, &v, &w, &thickness, &friction};
    deformable::Bvh<3> tree;
    const auto contacts = deformable::findFaceContacts<3>(bodies, set, tree);
    ASSERT_EQ(contacts.size(), 1u) << "trial " << trial;
    Eigen::Vector3d P0, Lz0, P1, L1;
    momenta(P0, Lz0);
    const bool anyFixed = std::find(w.begin(), w.end(), 0.0) != w.end();
    const int applied = deformable::applyFaceContactImpulses<3>(bodies, set, contacts, 4);
    if (applied > 0) ++approaching;  // a deep box corner may have a sideways normal
    momenta(P1, L1);
    // Relative normal velocity at the contact point after the sweeps: not approaching.
    const auto& c = contacts[0];
    Eigen::Vector3d faceV = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) faceV += c.weights[i] * Eigen::Vector3d(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
    const Eigen::Vector3d r = c.point - bodies[0].x;
    EXPECT_GE((faceV - bodies[0].v - bodies[0].omega.cross(r)).dot(c.normal), -1e-12) << "trial " << trial;
    if (anyFixed) continue;  // a fixed particle takes momentum out of the system
    EXPECT_LT((P1 - P0).norm(), 1e-13 * P0.norm()) << "trial " << trial;
    EXPECT_LT((L1 - Lz0).norm(), 1e-13 * (1 + Lz0.norm())) << "trial " << trial;
  }
  EXPECT_GE(approaching, 40);
}

// 2-D: a disk of radius 0.03 over the middle of a 0.2 m segment, falling: caught at the segment's
// interior, and the momentum kept.
TEST(RigidFaceContact, DiskOverSegmentIn2D) {
  const collision::PreparedGeometry<2> g(sphere<2>(0.03));
  std::vector<RigidFaceBody<2>> bodies(1);
  bodies[0].geometry = &g;
  bodies[0].x = Eigen::Vector2d(0.07, 0.032);
  bodies[0].v = Eigen::Vector2d(0.3, -1.5);
  bodies[0].inverseMass = 1 / 0.2;
  bodies[0].inverseInertia(0, 0) = 1 / (0.5 * 0.2 * 0.03 * 0.03);
  std::vector<int> faces = {0, 1};
  std::vector<double> x = {0, 0, 0.2, 0}, v = {0, 0, 0, 0}, w = {1 / 0.01, 1 / 0.02}, thickness(2, 0.005),
                      friction(2, 0.0);
  deformable::FaceSet<2> set{&faces, &x, &v, &w, &thickness, &friction};
  deformable::Bvh<2> tree;
  const auto contacts = deformable::findFaceContacts<2>(bodies, set, tree);
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_NEAR(contacts[0].distance, 0.002, 1e-15);
  EXPECT_NEAR(contacts[0].weights[1], 0.35, 1e-15);
  const Eigen::Vector2d P0 = 0.2 * bodies[0].v;
  deformable::applyFaceContactImpulses<2>(bodies, set, contacts, 4);
  const Eigen::Vector2d P1 = 0.2 * bodies[0].v + 0.01 * Eigen::Vector2d(v[0], v[1]) + 0.02 * Eigen::Vector2d(v[2], v[3]);
  EXPECT_LT((P1 - P0).norm(), 1e-15);
  // Frictionless: the disk keeps its x velocity; the point of the segment under it moves with it
  // along y.
  EXPECT_NEAR(bodies[0].v.x(), 0.3, 1e-15);
  EXPECT_NEAR(0.65 * v[1] + 0.35 * v[3], bodies[0].v.y(), 1e-12);
}

// Deformable surface collisions (solvers/deformable/proximity.h, Bridson et al. 2002): a point
// moving through a triangle and an edge through an edge in one step are stopped by the
// continuous collision pass, a pair inside the thickness is pushed apart by the proximity
// pass, linear momentum is conserved to round-off, the BVH finds what a brute-force search
// finds, and results are bitwise the same on 1 and 2 threads.
#include <gtest/gtest.h>

#include <oneapi/tbb/global_control.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <random>

#include "solvers/deformable/bvh.h"
#include "solvers/deformable/cloth.h"
#include "solvers/deformable/proximity.h"

namespace dm = monolith::solvers::deformable;

namespace {

template <int d>
Eigen::Matrix<double, d, 1> momentum(const std::vector<double>& v, const std::vector<double>& invMass) {
  Eigen::Matrix<double, d, 1> p = Eigen::Matrix<double, d, 1>::Zero();
  for (std::size_t i = 0; i < invMass.size(); ++i)
    if (invMass[i] > 0) p += Eigen::Map<const Eigen::Matrix<double, d, 1>>(&v[d * i]) / invMass[i];
  return p;
}

// Two free bodies: a triangle (particles 0-2) and a point (particle 3), or two edges.
dm::CollisionSurface<3> triangleAndPoint(double thickness) {
  dm::CollisionSurface<3> s;
  dm::addFaces<3>(s, {0, 1, 2}, 0, 3, thickness, 0.0, 0);
  // A lone point: a degenerate "face" list would add edges; add it by hand.
  s.points.push_back(3);
  s.thickness.push_back(thickness);
  s.friction.push_back(0.0);
  s.group.push_back(1);
  return s;
}

}  // namespace

TEST(DeformableProximity, PointThroughTriangleIsStopped) {
  const auto s = triangleAndPoint(0.01);
  std::vector<double> x = {0, 0, 0, 1, 0, 0, 0, 0, 1, 0.2, 0.05, 0.2};
  std::vector<double> v = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0.3, -10, 0.1};
  const std::vector<double> invMass = {1, 2, 0.5, 4};
  const double dt = 0.01;  // the point would end 0.05 below the plane, the triangle 0.01 above
  ASSERT_EQ(dm::countCollisions<3>(s, x, v, dt), 1);
  const Eigen::Vector3d p0 = momentum<3>(v, invMass);
  const auto r = dm::resolveCollisions<3>(s, x, v, invMass, dt, {});
  EXPECT_GE(r.collisions, 1);
  EXPECT_EQ(r.remaining, 0);
  EXPECT_EQ(dm::countCollisions<3>(s, x, v, dt), 0);
  EXPECT_LT((momentum<3>(v, invMass) - p0).norm(), 1e-13 * p0.norm());
  // The point now leaves the triangle's plane no faster than the triangle: it stays above.
  EXPECT_GE(x[10] + dt * v[10], (x[1] + dt * v[1]) * 0.6 + (x[4] + dt * v[4]) * 0.2 + (x[7] + dt * v[7]) * 0.2);
}

TEST(DeformableProximity, EdgeThroughEdgeIsStopped) {
  dm::CollisionSurface<3> s;
  s.thickness.assign(4, 0.01);
  s.friction.assign(4, 0.0);
  s.group = {0, 0, 1, 1};
  s.edges = {0, 1, 2, 3};
  // Edge 0-1 along x at y = 0, edge 2-3 along z at y = 0.05 falling through it.
  std::vector<double> x = {-1, 0, 0, 1, 0, 0, 0, 0.05, -1, 0.1, 0.05, 1};
  std::vector<double> v = {0, 0, 0, 0, 0, 0, 0, -10, 0, 0, -9, 0};
  const std::vector<double> invMass = {1, 1, 1, 1};
  const double dt = 0.01;
  ASSERT_EQ(dm::countCollisions<3>(s, x, v, dt), 1);
  const Eigen::Vector3d p0 = momentum<3>(v, invMass);
  const auto r = dm::resolveCollisions<3>(s, x, v, invMass, dt, {});
  EXPECT_EQ(r.remaining, 0);
  EXPECT_EQ(dm::countCollisions<3>(s, x, v, dt), 0);
  EXPECT_LT((momentum<3>(v, invMass) - p0).norm(), 1e-13 * p0.norm());
}

// Inside the thickness and approaching: the proximity pass leaves the pair separating at the
// repulsion rate 0.1 (h - distance) / dt, with the momentum unchanged.
TEST(DeformableProximity, ProximityRepelsWithinThickness) {
  const double h = 0.01, dt = 1e-3, gap = 0.004;
  const auto s = triangleAndPoint(h);
  std::vector<double> x = {0, 0, 0, 1, 0, 0, 0, 0, 1, 0.25, gap, 0.25};
  std::vector<double> v = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, -0.5, 0};
  const std::vector<double> invMass = {1, 1, 1, 1};
  const Eigen::Vector3d p0 = momentum<3>(v, invMass);
  const auto r = dm::repelProximities<3>(s, x, v, invMass, dt, {});
  EXPECT_EQ(r.repulsions, 1);
  EXPECT_NEAR(r.closest, gap, 1e-15);
  const double relative = v[10] - (0.5 * v[1] + 0.25 * v[4] + 0.25 * v[7]);
  EXPECT_NEAR(relative, 0.1 * (h - gap) / dt, 1e-12);
  EXPECT_LT((momentum<3>(v, invMass) - p0).norm(), 1e-15);
}

TEST(DeformableProximity, PointThroughSegmentIsStoppedIn2D) {
  dm::CollisionSurface<2> s;
  dm::addFaces<2>(s, {0, 1}, 0, 2, 0.01, 0.0, 0);
  s.points.push_back(2);
  s.thickness.push_back(0.01);
  s.friction.push_back(0.0);
  s.group.push_back(1);
  std::vector<double> x = {-1, 0, 1, 0, 0.3, 0.05};
  std::vector<double> v = {0, 0, 0, 0, 0, -20};
  const std::vector<double> invMass = {1, 1, 1};
  ASSERT_EQ(dm::countCollisions<2>(s, x, v, 0.01), 1);
  const auto r = dm::resolveCollisions<2>(s, x, v, invMass, 0.01, {});
  EXPECT_EQ(r.remaining, 0);
  EXPECT_EQ(dm::countCollisions<2>(s, x, v, 0.01), 0);
  EXPECT_LT(std::abs(momentum<2>(v, invMass).y() + 20), 1e-13);
}

TEST(DeformableProximity, BvhFindsWhatBruteForceFinds) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1), w(0.001, 0.08);
  std::vector<dm::Box<3>> boxes(500);
  for (auto& b : boxes) {
    b.lo = Eigen::Vector3d(u(rng), u(rng), u(rng));
    b.hi = b.lo + Eigen::Vector3d(w(rng), w(rng), w(rng));
  }
  dm::Bvh<3> tree;
  tree.build(boxes);
  for (int q = 0; q < 100; ++q) {
    std::vector<int> found;
    tree.query(boxes[q], found);
    std::sort(found.begin(), found.end());
    std::vector<int> brute;
    for (int k = 0; k < 500; ++k)
      if (boxes[k].overlaps(boxes[q])) brute.push_back(k);
    EXPECT_EQ(found, brute) << "query " << q;
  }
}

namespace {

// Two cloth sheets, one above the other, moving into each other with random velocities; the
// upper sheet's particles follow the lower one's.
struct TwoSheets {
  dm::CollisionSurface<3> s;
  std::vector<double> x, v, invMass;
};

TwoSheets twoSheets() {
  TwoSheets t;
  const dm::ClothMeshData sheet = dm::sheetMesh(0.5, 0.5, 0.05);
  const int n = static_cast<int>(sheet.x.size());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int layer = 0; layer < 2; ++layer) {
    dm::addFaces<3>(t.s, sheet.triangles, layer * n, n, 0.005, 0.1, -1);
    for (const auto& p : sheet.x) {
      t.x.insert(t.x.end(), {p.x(), p.y() + 0.02 * layer + 0.003 * u(rng), p.z()});
      t.v.insert(t.v.end(), {0.5 * u(rng), (layer ? -3.0 : 3.0) + u(rng), 0.5 * u(rng)});
      t.invMass.push_back(1 / (0.5 + 0.25 * (u(rng) + 1)));
    }
  }
  return t;
}

}  // namespace

// Sheets 2 cm apart closing at 6 m/s pass through each other in one 10 ms step unless stopped:
// after the proximity and collision passes no pair crosses, the momentum is unchanged to
// round-off, and 1 and 2 threads give the same velocities bit for bit.
TEST(DeformableProximity, SheetsMovingThroughEachOtherAreStoppedOnAnyThreadCount) {
  std::vector<double> results[2];
  for (int threads : {1, 2}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    TwoSheets t = twoSheets();
    const double dt = 0.01;
    const int before = dm::countCollisions<3>(t.s, t.x, t.v, dt);
    EXPECT_GT(before, 100);
    const Eigen::Vector3d p0 = momentum<3>(t.v, t.invMass);
    dm::repelProximities<3>(t.s, t.x, t.v, t.invMass, dt, {});
    const auto r = dm::resolveCollisions<3>(t.s, t.x, t.v, t.invMass, dt, {});
    std::printf("threads %d: %d crossings before, %d collision impulses in %d passes, %d left\n", threads, before,
                r.collisions, r.passes, r.remaining);
    EXPECT_EQ(r.remaining, 0);
    EXPECT_EQ(dm::countCollisions<3>(t.s, t.x, t.v, dt), 0);
    EXPECT_LT((momentum<3>(t.v, t.invMass) - p0).norm(), 1e-12 * (1 + p0.norm()));
    results[threads - 1] = t.v;
  }
  EXPECT_TRUE(results[0] == results[1]);
}

namespace {

// Four sheets 2 cm apart, alternate ones moving up and down at about 3 m/s with random
// velocities (every layer crosses its neighbours within one 10 ms step); no friction.
TwoSheets fourSheets() {
  TwoSheets t;
  const dm::ClothMeshData sheet = dm::sheetMesh(0.3, 0.3, 0.05);
  const int n = static_cast<int>(sheet.x.size());
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int layer = 0; layer < 4; ++layer) {
    dm::addFaces<3>(t.s, sheet.triangles, layer * n, n, 0.005, 0.0, -1);
    for (const auto& p : sheet.x) {
      t.x.insert(t.x.end(), {p.x(), p.y() + 0.02 * layer + 0.003 * u(rng), p.z()});
      t.v.insert(t.v.end(), {0.5 * u(rng), (layer % 2 ? -3.0 : 3.0) + u(rng), 0.5 * u(rng)});
      t.invMass.push_back(1 / (0.5 + 0.25 * (u(rng) + 1)));
    }
  }
  return t;
}

Eigen::Vector3d angularMomentum(const std::vector<double>& x, const std::vector<double>& v,
                                const std::vector<double>& invMass) {
  Eigen::Vector3d L = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < invMass.size(); ++i)
    L += Eigen::Vector3d::Map(&x[3 * i]).cross(Eigen::Vector3d::Map(&v[3 * i])) / invMass[i];
  return L;
}

}  // namespace

// Rigid impact zones (Bridson et al. 2002, Sec. 7.4), the fail-safe when the collision passes do
// not converge: with the pass limit at 1, four sheets crossing each other are left with
// collisions; the impact zones then end with no crossing. On the crossing state itself, the zones
// alone remove every crossing and keep linear and angular momentum to round-off.
TEST(DeformableProximity, ImpactZonesEndWithNoCrossingWhenPassesDoNotConverge) {
  const double dt = 0.01;
  {
    TwoSheets t = fourSheets();
    ASSERT_GT(dm::countCollisions<3>(t.s, t.x, t.v, dt), 100);
    dm::ProximitySettings settings;
    settings.collisionPasses = 1;
    settings.impactZones = false;
    std::vector<double> v = t.v;
    const auto without = dm::resolveCollisions<3>(t.s, t.x, v, t.invMass, dt, settings);
    const int left = dm::countCollisions<3>(t.s, t.x, v, dt);
    settings.impactZones = true;
    const Eigen::Vector3d p0 = momentum<3>(t.v, t.invMass);
    const auto with = dm::resolveCollisions<3>(t.s, t.x, t.v, t.invMass, dt, settings);
    std::printf("one pass: %d collisions left (%d crossings); with impact zones: %d zones in %d rounds, %d left\n",
                without.remaining, left, with.impactZones, with.impactZoneRounds, with.remaining);
    EXPECT_GT(without.remaining, 0);
    EXPECT_GT(left, 0);
    EXPECT_GT(with.impactZones, 0);
    EXPECT_EQ(with.remaining, 0);
    EXPECT_EQ(dm::countCollisions<3>(t.s, t.x, t.v, dt), 0);
    EXPECT_LT((momentum<3>(t.v, t.invMass) - p0).norm(), 1e-12 * (1 + p0.norm()));
  }
  {
    TwoSheets t = fourSheets();
    const Eigen::Vector3d p0 = momentum<3>(t.v, t.invMass), L0 = angularMomentum(t.x, t.v, t.invMass);
    const auto r = dm::resolveImpactZones<3>(t.s, t.x, t.v, t.invMass, dt);
    const Eigen::Vector3d p1 = momentum<3>(t.v, t.invMass), L1 = angularMomentum(t.x, t.v, t.invMass);
    std::printf("zones alone: %d zones in %d rounds; momentum %.1e, angular momentum %.1e relative\n", r.impactZones,
                r.impactZoneRounds, (p1 - p0).norm() / p0.norm(), (L1 - L0).norm() / L0.norm());
    EXPECT_EQ(r.remaining, 0);
    EXPECT_EQ(dm::countCollisions<3>(t.s, t.x, t.v, dt), 0);
    EXPECT_LT((p1 - p0).norm(), 1e-12 * p0.norm());
    EXPECT_LT((L1 - L0).norm(), 1e-12 * L0.norm());
  }
}

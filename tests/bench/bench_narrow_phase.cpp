// Speed of the collision pipeline: ns per narrow-phase query for the main shape pairs
// (each resting/touching, so every query produces contacts; poses jittered by 1e-4 so the loop
// does not replay one configuration), and us per broad-phase call for N random boxes with both
// methods.
//
// usage: bench_narrow_phase [queries per pair, default 100000]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <random>
#include <vector>

#include "solvers/collision/broad_phase.h"
#include "solvers/collision/geometry.h"
#include "solvers/collision/narrow_phase.h"

using namespace monolith::solvers::collision;

namespace {

constexpr double kPi = 3.14159265358979323846;

using Clock = std::chrono::steady_clock;

Geometry<3> box3(double h) {
  Geometry<3> g;
  g.type = GeometryType::Box;
  g.halfExtents = Eigen::Vector3d::Constant(h);
  return g;
}
Geometry<3> shape3(GeometryType type, double radius, double halfHeight) {
  Geometry<3> g;
  g.type = type;
  g.radius = radius;
  g.halfHeight = halfHeight;
  return g;
}
Geometry<3> ground3() {
  Geometry<3> g;
  g.type = GeometryType::HalfSpace;
  g.normal = Eigen::Vector3d::UnitY();
  return g;
}
// A rounded convex: 62 points on a sphere of radius 0.5 (latitude/longitude grid).
Geometry<3> convexBall() {
  Geometry<3> g;
  g.type = GeometryType::Convex;
  g.vertices.push_back(Eigen::Vector3d(0, 0.5, 0));
  g.vertices.push_back(Eigen::Vector3d(0, -0.5, 0));
  for (int i = 1; i < 7; ++i)
    for (int j = 0; j < 10; ++j) {
      const double t = kPi * i / 7, p = 2 * kPi * j / 10;
      g.vertices.push_back(0.5 * Eigen::Vector3d(std::sin(t) * std::cos(p), std::cos(t), std::sin(t) * std::sin(p)));
    }
  return g;
}
Geometry<3> groundMesh() {
  Geometry<3> g;
  g.type = GeometryType::Mesh;
  const int n = 20;  // 20 x 20 quads, 800 triangles, over [-10, 10]^2
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) g.vertices.push_back(Eigen::Vector3d(-10 + 20.0 * i / n, 0, -10 + 20.0 * j / n));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int v = i * (n + 1) + j;
      g.triangles.push_back({v, v + 1, v + n + 2});
      g.triangles.push_back({v, v + n + 2, v + n + 1});
    }
  return g;
}
Geometry<2> polygon2(GeometryType type, double size) {
  Geometry<2> g;
  g.type = type;
  g.halfExtents = Eigen::Vector2d::Constant(size);
  g.radius = size;
  return g;
}

template <int d>
Pose<d> jittered(const Pose<d>& p, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1e-4, 1e-4);
  Pose<d> q = p;
  for (int i = 0; i < d; ++i) q.x[i] += u(rng);
  if constexpr (d == 3)
    q.R = Eigen::AngleAxisd(u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized()).toRotationMatrix() * p.R;
  else
    q.R = Eigen::Rotation2Dd(u(rng)).toRotationMatrix() * p.R;
  return q;
}

template <int d>
void benchPair(const char* name, const Geometry<d>& a, const Pose<d>& pa, const Geometry<d>& b, const Pose<d>& pb,
               int queries, double margin = 0) {
  const PreparedGeometry<d> ga(a), gb(b);
  std::mt19937 rng(1);
  std::vector<Pose<d>> poses;
  for (int i = 0; i < 1024; ++i) poses.push_back(jittered<d>(pa, rng));
  std::vector<ContactPoint<d>> out;
  out.reserve(64);
  ContactQuery query;
  query.margin = margin;
  long points = 0;
  double best = 1e300;
  for (int rep = 0; rep < 3; ++rep) {
    points = 0;
    const auto t0 = Clock::now();
    for (int i = 0; i < queries; ++i) {
      out.clear();
      points += findContacts<d>(ga, poses[i & 1023], gb, pb, query, out);
    }
    best = std::min(best, std::chrono::duration<double, std::nano>(Clock::now() - t0).count() / queries);
  }
  std::printf("| %-34s | %8.0f | %6.2f |\n", name, best, static_cast<double>(points) / queries);
}

template <int d>
void benchBroadPhase(int n, std::mt19937& rng) {
  using Box = Eigen::AlignedBox<double, d>;
  // Boxes of size 0.5..1.5 at a density of about one box per 2^d unit cells: a few pairs each.
  const double side = 2 * std::pow(static_cast<double>(n), 1.0 / d);
  std::uniform_real_distribution<double> where(0, side), size(0.25, 0.75);
  std::vector<Box> boxes;
  std::vector<char> flags(n + 1, 0);
  for (int i = 0; i < n; ++i) {
    Eigen::Matrix<double, d, 1> c, h;
    for (int k = 0; k < d; ++k) c[k] = where(rng), h[k] = size(rng);
    boxes.push_back(Box(c - h, c + h));
  }
  // Plus the ground: an unbounded box.
  boxes.push_back(Box(Eigen::Matrix<double, d, 1>::Constant(-1e30), Eigen::Matrix<double, d, 1>::Constant(1e30)));
  flags[n] = 1;
  // Between calls every box moves by ~0.01 (a time step), as in a simulation.
  std::vector<std::vector<Box>> frames(6, boxes);
  std::normal_distribution<double> step(0, 0.01);
  for (std::size_t f = 1; f < frames.size(); ++f)
    for (int i = 0; i < n; ++i) {
      Eigen::Matrix<double, d, 1> move;
      for (int k = 0; k < d; ++k) move[k] = step(rng);
      frames[f][i] = Box(frames[f - 1][i].min() + move, frames[f - 1][i].max() + move);
    }
  for (BroadPhaseMethod method : {BroadPhaseMethod::SweepAndPrune, BroadPhaseMethod::FclDynamicTree}) {
    BroadPhase<d> broad(method);
    std::size_t pairs = broad.findPairs(frames[0], flags).size();  // warm up the buffers
    double best = 1e300;
    for (std::size_t f = 1; f < frames.size(); ++f) {
      const auto t0 = Clock::now();
      pairs = broad.findPairs(frames[f], flags).size();
      best = std::min(best, std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
    }
    std::printf("| %d-D | %5d | %-15s | %9.1f | %6zu |\n", d, n,
                method == BroadPhaseMethod::SweepAndPrune ? "sweep and prune" : "FCL AABB tree", best, pairs);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const int queries = argc > 1 ? std::atoi(argv[1]) : 100000;
  using V3 = Eigen::Vector3d;
  using V2 = Eigen::Vector2d;
  auto at = [](const V3& x, const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity()) {
    Pose<3> p;
    p.x = x;
    p.R = R;
    return p;
  };
  auto at2 = [](const V2& x, double angle = 0) {
    Pose<2> p;
    p.x = x;
    p.R = Eigen::Rotation2Dd(angle).toRotationMatrix();
    return p;
  };
  const Eigen::Matrix3d upright = Eigen::AngleAxisd(-kPi / 2, V3::UnitX()).toRotationMatrix();
  std::printf("Narrow phase, %d queries per pair (best of 3)\n\n", queries);
  std::printf("| %-34s | %8s | %6s |\n", "pair", "ns/query", "points");
  std::printf("|%s|%s|%s|\n", std::string(36, '-').c_str(), std::string(10, '-').c_str(), std::string(8, '-').c_str());
  benchPair<3>("box-box resting face", box3(0.3), at(V3(0.1, 0.79, 0.05), Eigen::AngleAxisd(0.4, V3::UnitY()).toRotationMatrix()),
               box3(0.5), at(V3::Zero()), queries);
  benchPair<3>("box-box edge-edge", box3(0.5),
               at(V3(0, std::sqrt(2.0) - 0.01, 0), Eigen::AngleAxisd(kPi / 4, V3::UnitZ()).toRotationMatrix()), box3(0.5),
               at(V3::Zero(), Eigen::AngleAxisd(kPi / 4, V3::UnitX()).toRotationMatrix()), queries);
  benchPair<3>("box-box resting, margin 0.01", box3(0.3), at(V3(0.1, 0.79, 0.05)), box3(0.5), at(V3::Zero()), queries,
               0.01);
  // A pyramid's pair: a unit box half on another, 1e-4 deep, with the contact thickness 1e-4.
  benchPair<3>("box-box pyramid, margin 1e-4", box3(0.5), at(V3(0.51, 0.9999, 0)), box3(0.5), at(V3::Zero()), queries,
               1e-4);
  benchPair<3>("box-halfspace", box3(0.5), at(V3(0, 0.49, 0)), ground3(), at(V3::Zero()), queries);
  benchPair<3>("sphere-sphere", shape3(GeometryType::Sphere, 0.5, 0), at(V3(0.1, 0.99, 0)),
               shape3(GeometryType::Sphere, 0.5, 0), at(V3::Zero()), queries);
  benchPair<3>("sphere-box", shape3(GeometryType::Sphere, 0.5, 0), at(V3(0.1, 0.99, 0)), box3(0.5), at(V3::Zero()), queries);
  benchPair<3>("sphere-halfspace", shape3(GeometryType::Sphere, 0.5, 0), at(V3(0.1, 0.49, 0)), ground3(), at(V3::Zero()), queries);
  benchPair<3>("capsule-halfspace (lying)", shape3(GeometryType::Capsule, 0.2, 0.5), at(V3(0, 0.19, 0)), ground3(),
               at(V3::Zero()), queries);
  benchPair<3>("cylinder-halfspace (standing)", shape3(GeometryType::Cylinder, 0.2, 0.5), at(V3(0, 0.49, 0), upright),
               ground3(), at(V3::Zero()), queries);
  benchPair<3>("capsule-box (lying)", shape3(GeometryType::Capsule, 0.2, 0.4), at(V3(0.1, 0.69, 0)), box3(0.5),
               at(V3::Zero()), queries);
  benchPair<3>("cylinder-box (standing)", shape3(GeometryType::Cylinder, 0.2, 0.3), at(V3(0.1, 0.79, 0), upright),
               box3(0.5), at(V3::Zero()), queries);
  benchPair<3>("convex-convex (62-vertex balls)", convexBall(), at(V3(0.1, 0.95, 0)), convexBall(), at(V3::Zero()), queries);
  {
    Geometry<3> cube = box3(0.5);
    cube.type = GeometryType::Convex;
    for (int c = 0; c < 8; ++c) cube.vertices.push_back(V3(c & 1 ? 0.3 : -0.3, c & 2 ? 0.3 : -0.3, c & 4 ? 0.3 : -0.3));
    benchPair<3>("convex cube-box resting", cube, at(V3(0.1, 0.79, 0)), box3(0.5), at(V3::Zero()), queries);
  }
  benchPair<3>("sphere-mesh (800 triangles)", shape3(GeometryType::Sphere, 0.5, 0), at(V3(0.3, 0.49, 0.2)), groundMesh(),
               at(V3::Zero()), queries);
  benchPair<3>("box-mesh (800 triangles)", box3(0.4), at(V3(0.3, 0.39, 0.2)), groundMesh(), at(V3::Zero()), queries);
  benchPair<2>("2-D polygon-polygon (box on box)", polygon2(GeometryType::Box, 0.3), at2(V2(0.1, 0.79), 0.05),
               polygon2(GeometryType::Box, 0.5), at2(V2::Zero()), queries);
  benchPair<2>("2-D disk-polygon", polygon2(GeometryType::Sphere, 0.3), at2(V2(0.1, 0.79)), polygon2(GeometryType::Box, 0.5),
               at2(V2::Zero()), queries);
  {
    Geometry<2> plane;
    plane.type = GeometryType::HalfSpace;
    plane.normal = V2::UnitY();
    benchPair<2>("2-D box-half-plane", polygon2(GeometryType::Box, 0.5), at2(V2(0, 0.49)), plane, at2(V2::Zero()), queries);
  }

  std::printf("\nBroad phase (best of 5 calls, boxes moving between calls; N random boxes plus one unbounded "
              "ground box)\n\n");
  std::printf("| d   | N     | method          | us/call   | pairs  |\n");
  std::printf("|-----|-------|-----------------|-----------|--------|\n");
  std::mt19937 rng(42);
  for (int n : {250, 1000, 4000}) benchBroadPhase<3>(n, rng);
  for (int n : {250, 1000, 4000}) benchBroadPhase<2>(n, rng);
  return 0;
}

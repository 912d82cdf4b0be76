// Deformable–deformable and self collisions in whole scenes (systems/deformable_self_collision.h):
// two elastic balls collide without interpenetrating and keep their linear momentum to
// round-off; a folded cloth sheet closing on itself does not pass through itself, bitwise the
// same on 1 and 2 threads; the trampoline (Fig. 4.4, reduced) catches rigid balls and deformable
// tori with nothing passing through the cloth; bad input names the entity and the key.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <map>

#include "components/cloth.h"
#include "components/deformable.h"
#include "components/rigid_body.h"
#include "scenarios/checkpoint.h"
#include "scenarios/simulation.h"
#include "support/resume_check.h"
#include "support/scene_error.h"
#include "support/scenes.h"

using namespace monolith;
using test::builtins;
using test::diagnostic;
using test::kScenes;

namespace {

Particles<3>& particlesOf(Simulation<3>& sim, const std::string& name) {
  return *sim.world().get<Particles<3>>(*sim.world().find(name));
}

// The deepest particle of `p` inside a tetrahedron of the body `q` (0 if none): the smallest
// barycentric coordinate of the containing element, times the element's size.
double deepestInside(const Particles<3>& p, const Particles<3>& q, const SimplexMesh<3>& mesh) {
  double deepest = 0;
  for (int e = 0; e < mesh.elementCount(); ++e) {
    const int* n = &mesh.elements[4 * e];
    auto X = [&](int i) { return Eigen::Vector3d(q.x[3 * i], q.x[3 * i + 1], q.x[3 * i + 2]); };
    Eigen::Matrix3d D;
    for (int k = 0; k < 3; ++k) D.col(k) = X(n[k + 1]) - X(n[0]);
    const Eigen::Matrix3d Dinv = D.inverse();
    Eigen::Vector3d lo = X(n[0]), hi = X(n[0]);
    for (int k = 1; k < 4; ++k) {
      lo = lo.cwiseMin(X(n[k]));
      hi = hi.cwiseMax(X(n[k]));
    }
    for (int i = 0; i < p.count(); ++i) {
      const Eigen::Vector3d x(p.x[3 * i], p.x[3 * i + 1], p.x[3 * i + 2]);
      if ((x.array() < lo.array()).any() || (x.array() > hi.array()).any()) continue;
      const Eigen::Vector3d b = Dinv * (x - X(n[0]));
      const double smallest = std::min({b(0), b(1), b(2), 1 - b.sum()});
      if (smallest > 0) deepest = std::max(deepest, smallest * (hi - lo).minCoeff());
    }
  }
  return deepest;
}

}  // namespace

// Two neo-Hookean balls (coarser meshes and a shorter run than the scene's) meet off-centre at
// 2.5 m/s relative speed: no particle of either ends up inside the other's tetrahedra, nothing
// crosses the other's surface during any step, and the linear momentum is kept to 1e-12.
TEST(DeformableSurfaceCollisions, TwoBallsCollideWithoutInterpenetration) {
  const Registry registry = builtins();
  Simulation<3> sim(loadScene(kScenes + "deformable_balls_collide.json",
                              {{"time.end", "0.2"},
                               {"entities.left.deformable.mesh.sphere.edge_length", "0.05"},
                               {"entities.right.deformable.mesh.sphere.edge_length", "0.05"}}),
                    registry);
  double p0 = 0, worstMomentum = 0, worstDepth = 0, crossings = 0, repulsions = 0;
  bool first = true;
  while (!sim.finished()) {
    const auto& m = sim.step();
    const double px = diagnostic(m, "linear_momentum_x");
    if (first) p0 = px;
    first = false;
    worstMomentum = std::max(worstMomentum, std::abs(px - p0) / std::abs(p0));
    crossings = std::max(crossings, diagnostic(m, "surface_crossings"));
    repulsions += diagnostic(m, "self_collision_repulsions");
    if (sim.stepsDone() % 25 == 0) {
      auto& world = sim.world();
      const auto left = *world.find("left"), right = *world.find("right");
      const auto& pl = *world.get<Particles<3>>(left);
      const auto& pr = *world.get<Particles<3>>(right);
      worstDepth = std::max({worstDepth, deepestInside(pl, pr, *world.get<SimplexMesh<3>>(right)),
                             deepestInside(pr, pl, *world.get<SimplexMesh<3>>(left))});
    }
  }
  const auto& left = particlesOf(sim, "left");
  double leftMomentum = 0;
  for (int i = 0; i < left.count(); ++i) leftMomentum += left.m[i] * left.v[3 * i];
  std::printf("balls: %ld steps, momentum drift %.2e, deepest particle inside the other ball %.2e m, %g crossings, "
              "%g repulsions, left ball's momentum %.4f of %.4f\n",
              sim.stepsDone(), worstMomentum, worstDepth, crossings, repulsions, leftMomentum, p0);
  EXPECT_LT(worstMomentum, 1e-12);
  EXPECT_EQ(worstDepth, 0.0);
  EXPECT_EQ(crossings, 0.0);
  EXPECT_GT(repulsions, 0.0);                    // they touched
  EXPECT_LT(leftMomentum, 0.8 * 1.5 * 4.18879);  // and the left ball gave momentum away
}

namespace {

const char* kFoldedSheet = R"({
  "dimension": 3,
  "time": { "cfl": 0.5, "dt": 0.01, "end": 0.12 },
  "gravity": [0, 0, 0],
  "entities": [
    { "name": "sheet",
      "cloth": { "mesh": { "sheet": { "half_extents": [0.3, 0.15], "edge_length": 0.05 } },
        "density": 0.2, "stretch_stiffness": 500, "bend_stiffness": 2, "overdamping": 0.2 },
      "surface_collision": { "thickness": 0.008, "friction": 0.2 } } ] })";

// Folds the flat sheet about x = 0: the half x < 0 stays at y = 0 moving up at 2 m/s, the half
// x > 0 is mirrored to lie 3 cm above it, moving down at 2 m/s. Returns the particle pairs
// (bottom, top) that start one above the other.
std::vector<std::pair<int, int>> foldSheet(Particles<3>& p, const ClothMesh& mesh) {
  const double gap = 0.03;
  std::map<std::pair<long, long>, int> at;
  for (int i = 0; i < p.count(); ++i) {
    const double x = mesh.restX[3 * i], z = mesh.restX[3 * i + 2];
    if (x > 1e-9) {
      p.x[3 * i] = -x;
      p.x[3 * i + 1] = gap;
      p.v[3 * i + 1] = -2;
    } else if (x < -1e-9) {
      p.v[3 * i + 1] = 2;
    } else {
      p.x[3 * i + 1] = gap / 2;
    }
    at[{std::lround(x * 1e6), std::lround(z * 1e6)}] = i;
  }
  std::vector<std::pair<int, int>> pairs;
  for (const auto& [key, i] : at)
    if (key.first < 0) pairs.emplace_back(i, at.at({-key.first, key.second}));
  return pairs;
}

}  // namespace

// The two layers of a folded sheet close on each other at 4 m/s. Without the self collisions
// they would pass through each other within 8 ms; with them every top particle stays above its
// bottom partner, nothing crosses during any step, the momentum is unchanged to round-off, and
// the runs on 1 and 2 threads agree bitwise after every step.
TEST(DeformableSurfaceCollisions, FoldedSheetDoesNotPassThroughItself) {
  const Registry registry = builtins();
  Simulation<3> one(parseScene(kFoldedSheet, "folded_sheet.json"), registry, 1);
  Simulation<3> two(parseScene(kFoldedSheet, "folded_sheet.json"), registry, 2);
  std::vector<std::pair<int, int>> pairs;
  for (Simulation<3>* sim : {&one, &two}) {
    auto& world = sim->world();
    const auto e = *world.find("sheet");
    pairs = foldSheet(*world.get<Particles<3>>(e), *world.get<ClothMesh>(e));
  }
  ASSERT_EQ(pairs.size(), 42u);  // 6 columns of 7 particles on each side of the fold
  double smallestGap = 1, crossings = 0, impulses = 0, drift = 0;
  while (!one.finished()) {
    const auto m = one.step();
    two.step();
    ASSERT_EQ(stateHash(one.world()), stateHash(two.world())) << "step " << one.stepsDone();
    crossings = std::max(crossings, diagnostic(m, "surface_crossings"));
    impulses += diagnostic(m, "self_collision_repulsions") + diagnostic(m, "self_collision_impulses");
    drift = std::max(drift, std::abs(diagnostic(m, "linear_momentum_y")));
    const auto& p = particlesOf(one, "sheet");
    for (auto [bottom, top] : pairs) smallestGap = std::min(smallestGap, p.x[3 * top + 1] - p.x[3 * bottom + 1]);
  }
  std::printf("folded sheet: %ld steps, smallest layer gap %.4f m, %g crossings, %g impulses, |p_y| <= %.2e\n",
              one.stepsDone(), smallestGap, crossings, impulses, drift);
  EXPECT_GT(smallestGap, 0.0);
  EXPECT_EQ(crossings, 0.0);
  EXPECT_GT(impulses, 0.0);
  EXPECT_LT(drift, 1e-12);
}

// Fig. 4.4 reduced to 0.32 s (all bodies dropped from 0.25–0.3 m) and coarser tori: the balls
// and tori fall onto the cloth and are caught; no rigid body centre or torus particle passes through the cloth in any step, every
// collision pass ends collision-free, and the balls come to lie on the cloth (above the frame
// level minus the sag, below where they started).
TEST(DeformableSurfaceCollisions, TrampolineCatchesBallsAndToriWithoutPassThrough) {
  const Registry registry = builtins();
  Simulation<3> sim(loadScene(kScenes + "trampoline.json",
                              {{"time.end", "0.32"},
                               {"entities.ball1.rigid_body.position", "[0.2, 0.3, 0.15]"},
                               {"entities.torus1.deformable.position", "[-0.15, 0.3, 0.2]"},
                               {"entities.torus0.deformable.mesh.torus.edge_length", "0.04"},
                               {"entities.torus1.deformable.mesh.torus.edge_length", "0.04"}}),
                    registry);
  double crossings = 0, remaining = 0, touches = 0;
  while (!sim.finished()) {
    const auto& m = sim.step();
    crossings = std::max(crossings, diagnostic(m, "surface_crossings"));
    remaining = std::max(remaining, diagnostic(m, "self_collision_remaining"));
    touches += diagnostic(m, "self_collision_repulsions");
  }
  auto& world = sim.world();
  const double y0 = world.get<RigidBody<3>>(*world.find("ball0"))->x.y();
  const double y1 = world.get<RigidBody<3>>(*world.find("ball1"))->x.y();
  double torusLow = 1;
  for (const char* name : {"torus0", "torus1"}) {
    const auto& p = particlesOf(sim, name);
    for (int i = 0; i < p.count(); ++i) torusLow = std::min(torusLow, p.x[3 * i + 1]);
  }
  std::printf("trampoline (reduced): %ld steps, balls at y = %.3f, %.3f, lowest torus particle %.3f, %g crossings, "
              "%g torus-cloth repulsions\n",
              sim.stepsDone(), y0, y1, torusLow, crossings, touches);
  EXPECT_EQ(crossings, 0.0);
  EXPECT_EQ(remaining, 0.0);
  EXPECT_GT(touches, 0.0);  // the tori reached the cloth
  for (double y : {y0, y1}) {
    EXPECT_LT(y, 0.25);
    EXPECT_GT(y, -0.4);  // caught, not fallen to the ground at -0.6
  }
  EXPECT_GT(torusLow, -0.4);
}

TEST(DeformableSurfaceCollisions, BadInputNamesEntityAndKey) {
  const auto error = test::sceneError;
  const std::string rigid = error(
      R"({ "dimension": 3, "time": { "dt": 0.001, "end": 0.01 }, "entities": [ { "name": "b",
      "shape": { "type": "sphere", "radius": 0.1 }, "rigid_body": { "mass": 1 },
      "surface_collision": { "thickness": 0.01 } } ] })");
  EXPECT_NE(rigid.find("entities[0].surface_collision"), std::string::npos) << rigid;
  EXPECT_NE(rigid.find("\"deformable\" or \"cloth\""), std::string::npos) << rigid;
  const std::string dynamicFrame = error(
      R"({ "dimension": 3, "time": { "dt": 0.001, "end": 0.01 }, "entities": [
      { "name": "f", "shape": { "type": "box", "half_extents": [0.1, 0.1, 0.1] }, "rigid_body": { "mass": 1 } },
      { "name": "c", "cloth": { "mesh": { "sheet": { "half_extents": [0.2, 0.2], "edge_length": 0.1 } },
        "stretch_stiffness": 100, "bind": [ { "body": "f", "min": [-1, -1, -1], "max": [-0.15, 1, 1] } ] } } ] })");
  EXPECT_NE(dynamicFrame.find("bind[0].body"), std::string::npos) << dynamicFrame;
  EXPECT_NE(dynamicFrame.find("static or kinematic"), std::string::npos) << dynamicFrame;
  const std::string noMesh = error(
      R"({ "dimension": 3, "time": { "dt": 0.001, "end": 0.01 }, "entities": [
      { "name": "c", "cloth": { "mesh": { "disk": {} }, "stretch_stiffness": 100 } } ] })");
  EXPECT_NE(noMesh.find("entities[0].cloth.mesh"), std::string::npos) << noMesh;
  const std::string torus = error(
      R"({ "dimension": 3, "time": { "dt": 0.001, "end": 0.01 }, "entities": [ { "name": "t", "deformable": {
      "mesh": { "torus": { "major_radius": 0.05, "minor_radius": 0.1, "edge_length": 0.02 } }, "youngs_modulus": 1e4 } } ] })");
  EXPECT_NE(torus.find("major_radius"), std::string::npos) << torus;
}

// A cloth draping over a ball with a deformable capsule on it, resumed from a checkpoint,
// reproduces the straight run bitwise: cloth meshes and materials and the surface_collision
// components are checkpointed; force models, surfaces and BVHs are caches rebuilt from them.
TEST(DeformableSurfaceCollisions, ClothResumedRunMatchesStraightRunBitwise) {
  test::expectResumeMatchesStraightRun("cloth_drape.json", "0.06", {"--check"});
}

// 2-D: two neo-Hookean disks meet head-on; their boundary segments collide (point–segment
// proximity and collision): nothing crosses, the linear momentum is kept to round-off, and the
// disks bounce apart; 1 and 2 threads agree bitwise.
TEST(DeformableSurfaceCollisions, DisksCollideIn2D) {
  const char* scene = R"({
    "dimension": 2, "time": { "cfl": 0.5, "dt": 0.01, "end": 0.25 }, "gravity": [0, 0],
    "entities": [
      { "name": "a", "deformable": { "mesh": { "sphere": { "radius": 0.1, "edge_length": 0.025 } },
          "model": "neo_hookean", "youngs_modulus": 2e4, "density": 1000, "rayleigh_beta": 0.002,
          "position": [-0.12, 0.02], "velocity": [1, 0] },
        "surface_collision": { "thickness": 0.004 } },
      { "name": "b", "deformable": { "mesh": { "sphere": { "radius": 0.1, "edge_length": 0.025 } },
          "model": "neo_hookean", "youngs_modulus": 2e4, "density": 1000, "rayleigh_beta": 0.002,
          "position": [0.12, 0], "velocity": [-1, 0] },
        "surface_collision": { "thickness": 0.004 } } ] })";
  const Registry registry = builtins();
  Simulation<2> one(parseScene(scene, "disks.json"), registry, 1);
  Simulation<2> two(parseScene(scene, "disks.json"), registry, 2);
  double crossings = 0, repulsions = 0, drift = 0;
  while (!one.finished()) {
    const auto m = one.step();
    two.step();
    ASSERT_EQ(stateHash(one.world()), stateHash(two.world())) << "step " << one.stepsDone();
    crossings = std::max(crossings, diagnostic(m, "surface_crossings"));
    repulsions += diagnostic(m, "self_collision_repulsions");
    drift = std::max(drift, std::abs(diagnostic(m, "linear_momentum_x")));
  }
  const auto& a = *one.world().get<Particles<2>>(*one.world().find("a"));
  double va = 0, ma = 0;
  for (int i = 0; i < a.count(); ++i) {
    va += a.m[i] * a.v[2 * i];
    ma += a.m[i];
  }
  std::printf("disks 2-D: %ld steps, %g crossings, %g repulsions, |p_x| <= %.2e, disk a at %.3f m/s\n",
              one.stepsDone(), crossings, repulsions, drift, va / ma);
  EXPECT_EQ(crossings, 0.0);
  EXPECT_GT(repulsions, 0.0);
  EXPECT_LT(drift, 1e-12);
  EXPECT_LT(va / ma, 0.0);  // bounced back
}

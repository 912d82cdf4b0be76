// Interpenetration resolution with particles (systems/particle_contact.h, thesis Sec. 4.6.1,
// App. B): a deformable box pressed into a rigid box is pushed out two ways in one solve (the
// rigid body the central body, the particles inside it its outer bodies), both moving in the
// inverse ratio of their masses with the total first moment sum m x unchanged to round-off and
// the velocities untouched (linear momentum exactly); a
// particle wedged between two rigid boxes is the central body of the 3x3 solve and pushes both.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include "components/deformable.h"
#include "components/rigid_body.h"
#include "scenarios/scene.h"
#include "support/scenes.h"
#include "systems/particle_contact.h"

using namespace monolith;
using test::builtins;

namespace {

struct Moments {
  Eigen::Vector3d first = Eigen::Vector3d::Zero();  // sum m x
  Eigen::Vector3d momentum = Eigen::Vector3d::Zero();
  double mass = 0;
};

Moments moments(World<3>& w) {
  Moments out;
  w.each<RigidBody<3>>([&](Entity, RigidBody<3>& b) {
    if (b.isStatic) return;
    out.first += b.mass * b.x;
    out.momentum += b.mass * b.v;
    out.mass += b.mass;
  });
  w.each<Particles<3>>([&](Entity, Particles<3>& p) {
    for (int i = 0; i < p.count(); ++i) {
      const Eigen::Vector3d x(&p.x[3 * i]), v(&p.v[3 * i]);
      out.first += p.m[i] * x;
      out.momentum += p.m[i] * v;
      out.mass += p.m[i];
    }
  });
  return out;
}

// The deepest free particle inside any rigid body.
double deepestInside(World<3>& w) {
  ParticlePenetration<3> measure;
  StepContext ctx;
  measure.run(w, ctx);
  return test::diagnostic(ctx.diagnostics.values(), "max_penetration");
}

Eigen::Vector3d particleCentroid(const Particles<3>& p) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  double m = 0;
  for (int i = 0; i < p.count(); ++i) {
    c += p.m[i] * Eigen::Vector3d(&p.x[3 * i]);
    m += p.m[i];
  }
  return c / m;
}

std::map<std::string, double> pushOut(World<3>& w) {
  ParticlePushOut<3> push(std::make_shared<ParticleContactScratch>());
  StepContext ctx;
  push.run(w, ctx);
  return ctx.diagnostics.values();
}

}  // namespace

// A 0.2 m deformable box (8 kg) sunk 2 cm into the top of a 0.4 m rigid box (mass 2 or 32 kg),
// both moving: one push-out leaves no particle inside, the bodies move apart along y in the
// inverse ratio of their masses, and sum m x, the linear and angular momentum are unchanged.
TEST(ParticlePushOut, DeformableBoxAndRigidBoxMoveInTheirMassRatio) {
  const Registry registry = builtins();
  for (const double rigidMass : {2.0, 32.0}) {
    const std::string text = R"({"dimension": 3, "time": {"dt": 0.001, "end": 0.01}, "gravity": [0, 0, 0],
      "entities": [
        {"name": "box", "shape": {"type": "box", "half_extents": [0.2, 0.2, 0.2]},
         "rigid_body": {"mass": )" + std::to_string(rigidMass) + R"(, "velocity": [0.3, -0.2, 0.1], "angular_velocity": [0, 0.5, 0]},
         "collider": {"friction": 0.3}},
        {"name": "block", "deformable": {"mesh": {"box": {"half_extents": [0.1, 0.1, 0.1], "edge_length": 0.05}},
         "youngs_modulus": 1e5, "density": 1000, "position": [0, 0.28, 0], "velocity": [0, -1, 0]}}]})";
    World<3> world;
    populateWorld<3>(parseScene(text, "push_out.json"), registry, world);
    const Moments before = moments(world);
    const Particles<3>& p = *world.get<Particles<3>>(*world.find("block"));
    const RigidBody<3>& box = *world.get<RigidBody<3>>(*world.find("box"));
    const Eigen::Vector3d block0 = particleCentroid(p), box0 = box.x;
    int bottomParticle = 0;  // one of the particles sunk into the box
    while (p.x[3 * bottomParticle + 1] > 0.2) ++bottomParticle;
    const double depth0 = deepestInside(world);
    const auto diag = pushOut(world);
    const Moments after = moments(world);
    const Eigen::Vector3d dBlock = particleCentroid(p) - block0, dBox = box.x - box0;
    const double blockMass = before.mass - rigidMass;
    std::printf("rigid %g kg, block %g kg: depth %.3g -> %.3g; box moved %.6g, block %.6g (ratio %.6g, masses %.6g); "
                "sum m x change %.3g, momentum change %.3g; solves %g\n",
                rigidMass, blockMass, depth0, deepestInside(world), dBox.y(), dBlock.y(), -dBlock.y() / dBox.y(),
                rigidMass / blockMass, (after.first - before.first).norm(), (after.momentum - before.momentum).norm(), test::diagnostic(diag, "particle_push_out_body_solves"));
    EXPECT_NEAR(depth0, 0.02, 1e-12);
    EXPECT_LT(deepestInside(world), 1e-12);
    EXPECT_LT(dBox.y(), -1e-4);  // pushed down, the block up
    EXPECT_GT(dBlock.y(), 1e-4);
    EXPECT_NEAR(-dBlock.y() / dBox.y(), rigidMass / blockMass, 1e-9 * rigidMass / blockMass);
    // The sunk particle ends on the box's top face (the box also turns a little: the lumped masses
    // of the split cubes are not symmetric; the rotation is linearized in the solve).
    const Eigen::Vector3d local = box.rotation().transpose() * (Eigen::Vector3d(&p.x[3 * bottomParticle]) - box.x);
    const double turned = Eigen::AngleAxisd(box.orientation).angle();
    std::printf("  particle %d: %.3g above the face; box turned %.3g rad\n", bottomParticle, local.y() - 0.2, turned);
    EXPECT_NEAR(local.y(), 0.2, 1e-12 + 0.2 * turned * turned);
    EXPECT_LT((after.first - before.first).norm(), 1e-14 * before.mass);
    EXPECT_EQ((after.momentum - before.momentum).norm(), 0.0);  // positions only
  }
}

// A particle pressed 1 cm into each of two rigid boxes (1 and 3 kg) on either side: it is
// inside both, the central body of the 3x3 solve, and pushes both out; sum m x unchanged.
TEST(ParticlePushOut, ParticleWedgedBetweenTwoBodiesPushesBoth) {
  const Registry registry = builtins();
  const std::string text = R"({"dimension": 3, "time": {"dt": 0.001, "end": 0.01}, "gravity": [0, 0, 0],
    "entities": [
      {"name": "left", "shape": {"type": "box", "half_extents": [0.1, 0.1, 0.1]},
       "rigid_body": {"mass": 1, "position": [-0.09, 0, 0]}, "collider": {}},
      {"name": "right", "shape": {"type": "box", "half_extents": [0.1, 0.1, 0.1]},
       "rigid_body": {"mass": 3, "position": [0.09, 0, 0]}, "collider": {}},
      {"name": "p", "particle": {"mass": 0.5, "position": [0, 0, 0]}}]})";
  World<3> world;
  populateWorld<3>(parseScene(text, "wedge.json"), registry, world);
  const Moments before = moments(world);
  const auto diag = pushOut(world);
  const Moments after = moments(world);
  const RigidBody<3>& left = *world.get<RigidBody<3>>(*world.find("left"));
  const RigidBody<3>& right = *world.get<RigidBody<3>>(*world.find("right"));
  const Particles<3>& p = *world.get<Particles<3>>(*world.find("p"));
  std::printf("wedged particle: left %.6g, right %.6g, particle %.6g; particle solves %g, depth left %.3g; "
              "sum m x change %.3g\n",
              left.x.x(), right.x.x(), p.x[0], test::diagnostic(diag, "particle_push_out_particle_solves"),
              deepestInside(world), (after.first - before.first).norm());
  EXPECT_GE(test::diagnostic(diag, "particle_push_out_particle_solves"), 1.0);
  EXPECT_LT(left.x.x(), -0.09 - 1e-3);  // both bodies pushed away
  EXPECT_GT(right.x.x(), 0.09 + 1e-3);
  EXPECT_LT(deepestInside(world), 1e-9);
  EXPECT_LT((after.first - before.first).norm(), 1e-15 * before.mass);
}

// Against the ground (static), the rigid box under the deformable block does not move down: the
// ground is a static outer body of its solve (B.3), and the block takes the whole push.
TEST(ParticlePushOut, StaticSupportHoldsTheBody) {
  const Registry registry = builtins();
  const std::string text = R"({"dimension": 3, "time": {"dt": 0.001, "end": 0.01}, "gravity": [0, 0, 0],
    "entities": [
      {"name": "ground", "shape": {"type": "plane", "normal": [0, 1, 0]}, "rigid_body": {"static": true, "position": [0, -0.2, 0]}, "collider": {}},
      {"name": "box", "shape": {"type": "box", "half_extents": [0.2, 0.2, 0.2]}, "rigid_body": {"mass": 2}, "collider": {}},
      {"name": "block", "deformable": {"mesh": {"box": {"half_extents": [0.1, 0.1, 0.1], "edge_length": 0.05}},
       "youngs_modulus": 1e5, "density": 1000, "position": [0, 0.28, 0]}}]})";
  World<3> world;
  populateWorld<3>(parseScene(text, "support.json"), registry, world);
  const Particles<3>& p = *world.get<Particles<3>>(*world.find("block"));
  const Eigen::Vector3d block0 = particleCentroid(p);
  double bottom = 0, total = 0;  // the particles sunk into the box (the bottom layer)
  for (int i = 0; i < p.count(); ++i) {
    total += p.m[i];
    if (p.x[3 * i + 1] < 0.2) bottom += p.m[i];
  }
  pushOut(world);
  const RigidBody<3>& box = *world.get<RigidBody<3>>(*world.find("box"));
  std::printf("on the ground: box y %.3g, block moved %.6g, depth left %.3g\n", box.x.y(), particleCentroid(p).y() - block0.y(),
              deepestInside(world));
  EXPECT_LT(std::abs(box.x.y()), 1e-9);
  EXPECT_NEAR(particleCentroid(p).y() - block0.y(), 0.02 * bottom / total, 1e-9);
  EXPECT_LT(deepestInside(world), 1e-9);
}

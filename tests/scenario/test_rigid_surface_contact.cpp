// Rigid bodies against cloth triangles in a whole scene (systems/rigid_surface_contact.h): a ball
// and a cube smaller than the sheet's cells, dropped on it, are caught by the triangles' interiors
// (the particle/rigid contact alone lets them through between the particles), with nothing
// crossing the cloth in any step and no energy gained.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>

#include "components/deformable.h"
#include "components/rigid_body.h"
#include "scenarios/checkpoint.h"
#include "scenarios/simulation.h"
#include "support/scenes.h"

using namespace monolith;
using test::builtins;
using test::diagnostic;
using test::kScenes;

// small_bodies_on_cloth.json without its deformable ball: a rigid ball (r = 0.03 m) and cube
// (0.04 m, corner first) on a sheet of 0.1 m cells, 0.8 s.
TEST(RigidSurfaceContact, BodiesSmallerThanACellAreCaughtByTheSheet) {
  const Registry registry = builtins();
  Simulation<3> sim(loadScene(kScenes + "small_bodies_on_cloth.json",
                              {{"entities.soft_ball.deformable.position", "[5, 0, 5]"}, {"entities.soft_ball.deformable.youngs_modulus", "100"}}),
                    registry);
  double crossings = 0, faceImpulses = 0, energy0 = -1, energyMax = 0, lowest[2] = {1, 1};
  const char* names[2] = {"ball", "cube"};
  auto body = [&](const char* name) { return sim.world().get<RigidBody<3>>(*sim.world().find(name)); };
  while (!sim.finished()) {
    const auto& m = sim.step();
    crossings = std::max(crossings, diagnostic(m, "surface_crossings"));
    faceImpulses += diagnostic(m, "rigid_surface_collisions_impulses") + diagnostic(m, "rigid_surface_velocity_contact_impulses");
    // The soft ball falls freely far away: its energy stays constant up to the integrator's.
    if (energy0 < 0) energy0 = diagnostic(m, "total_energy");
    energyMax = std::max(energyMax, diagnostic(m, "total_energy"));
    for (int k = 0; k < 2; ++k) lowest[k] = std::min(lowest[k], body(names[k])->x.y());
  }
  std::printf("small bodies on cloth: %ld steps, %g face impulses, %g crossings, lowest y ball %.4f cube %.4f, "
              "final y %.4f %.4f, energy %.5f -> max %.5f\n",
              sim.stepsDone(), faceImpulses, crossings, lowest[0], lowest[1], body("ball")->x.y(), body("cube")->x.y(),
              energy0, energyMax);
  EXPECT_EQ(crossings, 0.0);
  EXPECT_GT(faceImpulses, 0.0);
  EXPECT_GT(lowest[0], -0.1);  // caught in the sheet (it sags); through it, they fall freely
  EXPECT_GT(lowest[1], -0.1);
  EXPECT_LT(body("ball")->x.y(), 0.1);  // and not thrown off
  EXPECT_LT(body("cube")->x.y(), 0.1);
  EXPECT_LT(energyMax, energy0 * (1 + 1e-3));
}

// Through the first landings (the ball and the cube meet the sheet at about 0.15 s): 1 and 2
// threads give bitwise the same state after every step.
TEST(RigidSurfaceContact, OneAndTwoThreadsAgreeBitwise) {
  const Registry registry = builtins();
  const std::vector<Override> o = {{"time.end", "0.25"},
                                   {"entities.soft_ball.deformable.position", "[5, 0, 5]"},
                                   {"entities.soft_ball.deformable.youngs_modulus", "100"}};
  Simulation<3> one(loadScene(kScenes + "small_bodies_on_cloth.json", o), registry, 1);
  Simulation<3> two(loadScene(kScenes + "small_bodies_on_cloth.json", o), registry, 2);
  double impulses = 0;
  while (!one.finished()) {
    impulses += diagnostic(one.step(), "rigid_surface_collisions_impulses");
    two.step();
    ASSERT_EQ(stateHash(one.world()), stateHash(two.world())) << "step " << one.stepsDone();
  }
  EXPECT_GT(impulses, 0.0);
}

// The swept test: a ball of radius 0.03 m at 30 m/s onto a slack sheet (1 N/m, so the steps are
// long: 2 ms) moves 6 cm a step, twice its radius, and without the swept test its centre passed
// between the discrete tests' positions straight through a cell (1 crossing, the ball then
// falling on freely). Swept, the crossing face stops it.
TEST(RigidSurfaceContact, FastSmallBallDoesNotTunnel) {
  const Registry registry = builtins();
  Simulation<3> sim(loadScene(kScenes + "small_bodies_on_cloth.json",
                              {{"time.end", "0.03"},
                               {"gravity", "[0, 0, 0]"},
                               {"entities.soft_ball.deformable.position", "[5, 0, 5]"},
                               {"entities.soft_ball.deformable.youngs_modulus", "100"},
                               {"entities.cube.rigid_body.position", "[5, 0, -5]"},
                               {"entities.ball.rigid_body.position", "[0.02, 0.04, 0.05]"},
                               {"entities.ball.rigid_body.velocity", "[0, -30, 0]"},
                               {"entities.cloth.cloth.stretch_stiffness", "1"},
                               {"entities.cloth.cloth.bend_stiffness", "0.01"}}),
                    registry);
  double crossings = 0, swept = 0, longest = 0;
  while (!sim.finished()) {
    const auto& m = sim.step();
    crossings = std::max(crossings, diagnostic(m, "surface_crossings"));
    swept += diagnostic(m, "rigid_surface_swept_contacts");
    longest = std::max(longest, sim.lastDt());
  }
  const double ballY = sim.world().get<RigidBody<3>>(*sim.world().find("ball"))->x.y();
  const Particles<3>& cloth = *sim.world().get<Particles<3>>(*sim.world().find("cloth"));
  double lowest = 1;
  for (int i = 0; i < cloth.count(); ++i) lowest = std::min(lowest, cloth.x[3 * i + 1]);
  std::printf("fast ball: %ld steps of up to %.3g s (%.3g m at 30 m/s), %g swept contacts, %g crossings, ball at y = %.4f, "
              "the slack sheet's lowest particle at %.4f\n",
              sim.stepsDone(), longest, 30 * longest, swept, crossings, ballY, lowest);
  EXPECT_GT(30 * longest, 0.06);  // a step carries the ball over its diameter
  EXPECT_GE(swept, 1.0);
  EXPECT_EQ(crossings, 0.0);
  EXPECT_LT(lowest, ballY - 0.02);  // the sheet carried down under the ball, not left above it
}

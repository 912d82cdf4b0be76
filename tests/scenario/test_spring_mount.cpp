// spring_mount (components/spring_mount.h): a mounted body oscillates about its anchor at
// omega = sqrt(k / m) (the Newmark steps are velocity Verlet for this explicit force: the phase
// error is O(dt^2), 2e-4 of a period at 200 steps per period); a static body is refused.
#include <gtest/gtest.h>

#include <cmath>

#include "components/rigid_body.h"
#include "scenarios/scene.h"
#include "scenarios/simulation.h"
#include "support/scenes.h"

using namespace monolith;
using namespace monolith::test;

TEST(SpringMount, BodyOscillatesAtTheSpringFrequency) {
  const Registry registry = builtins();
  // m = 2, k = 8: omega = 2, period pi; start 0.1 off the anchor, at rest.
  const double period = M_PI, dt = period / 200;
  const std::string text = R"({"dimension": 2, "time": {"dt": )" + std::to_string(dt) + R"(, "steps": 100},
    "entities": [ {"name": "b", "shape": {"type": "disk", "radius": 0.1},
      "rigid_body": {"mass": 2, "position": [0.1, 0]},
      "spring_mount": {"anchor": [0, 0], "stiffness": [8, 8]} } ] })";
  Simulation<2> sim(parseScene(text, "spring.json"), registry, 1);
  while (!sim.finished()) sim.step();
  const RigidBody<2>& b = *sim.world().get<RigidBody<2>>(*sim.world().find("b"));
  // Half a period: x = -0.1, v = 0 (to the scheme's O(dt^2) phase error).
  EXPECT_NEAR(b.x.x(), -0.1, 1e-4);
  EXPECT_NEAR(b.v.x(), 0.0, 2e-3);
  EXPECT_EQ(b.x.y(), 0.0);
}

TEST(SpringMount, StaticBodyIsRefused) {
  const Registry registry = builtins();
  const std::string text = R"({"dimension": 2, "time": {"dt": 0.01, "steps": 1},
    "entities": [ {"name": "b", "shape": {"type": "disk", "radius": 0.1}, "rigid_body": {"static": true},
      "spring_mount": {"stiffness": [8, 8]} } ] })";
  World<2> world;
  try {
    populateWorld(parseScene(text, "spring.json"), registry, world);
    ADD_FAILURE() << "accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(e.path().find("entities[0].spring_mount"), std::string::npos) << e.what();
  }
}

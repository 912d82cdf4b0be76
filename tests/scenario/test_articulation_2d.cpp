// Articulated rigid bodies in 2-D (thesis Sec. 4.4-4.7, App. C, in the plane): pins, fixed and
// prismatic joints through the same joint solver as 3-D (the joints of the plane z = 0). The
// pendulum's period against the closed form, energy that never rises at dt = 1/30, a falling
// chain that stays joined on 1 and 2 threads bitwise, global and pairwise post-stabilization
// agreeing at convergence, a slider in free fall along its rail, PD overshoot as its gains
// predict, angle limits, checkpoints, and validation at JSON paths.
#include <gtest/gtest.h>

#include "support/oscillation.h"
#include "support/resume_check.h"
#include "support/scene_error.h"
#include "support/scenes.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "components/joint.h"
#include "components/rigid_body.h"
#include "scenarios/checkpoint.h"
#include "scenarios/simulation.h"

using namespace monolith;
using test::bodyNamed;
using test::builtins;
using test::kScenes;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.81;


// Angle of the rod of pendulum_2d from hanging straight down.
double pendulumAngle(Simulation<2>& sim) {
  const Eigen::Vector2d x = bodyNamed(sim, "rod").x;
  return std::atan2(x.x(), -x.y());
}

// The scene text of one pinned or sliding body (and its joint) in a 2-D world without gravity
// unless given.
std::string singleBody(const std::string& rigid, const std::string& joint, double end, const std::string& gravity = "[0, 0]") {
  return R"({ "dimension": 2, "time": { "dt": 0.004166666666666667, "end": )" + std::to_string(end) +
         R"( }, "gravity": )" + gravity + R"(, "entities": [
    { "name": "link", "shape": { "type": "box", "half_extents": [0.5, 0.02] }, "rigid_body": )" +
         rigid + R"(, "joint": )" + joint + " } ] }";
}

}  // namespace

TEST(Articulation2d, PendulumPeriodMatchesTheClosedForm) {
  const Registry registry = builtins();
  Simulation<2> sim(loadScene(kScenes + "pendulum_2d.json"), registry);
  // I_pivot of the rod (box 0.02 x 1, 1 kg, centre 0.5 m down) and bob (disk r 0.1, 2 kg, 1 m down).
  const double I = (1.0 / 12 * (1.0 + 0.0004) + 0.25) + (0.5 * 2 * 0.01 + 2.0);
  const double m = 3, d = (0.5 * 1 + 1.0 * 2) / 3;
  const double expected = 2 * kPi * std::sqrt(I / (m * kG * d));
  std::vector<double> t{0.0}, angle{pendulumAngle(sim)};
  double worst = 0;
  while (!sim.finished()) {
    worst = std::max(worst, sim.step().at("joint_error_max"));
    t.push_back(sim.time());
    angle.push_back(pendulumAngle(sim));
  }
  const test::Oscillation swing = test::analyseOscillation(t, angle, 0.0);
  ASSERT_GE(swing.crossings, 4);
  const double period = swing.period;
  std::cout << "[measured] pendulum_2d period " << period << " s, closed form " << expected << " s ("
            << 100 * (period / expected - 1) << " %), joint_error_max " << worst << " m\n";
  // 0.5 %: the issue's bound; the 5 degree amplitude alone lengthens the period by 0.048 %.
  EXPECT_NEAR(period / expected, 1.0, 0.005);
  EXPECT_LT(worst, 1e-8);
}

TEST(Articulation2d, PendulumAtLargeStepsNeverGainsEnergy) {
  const Registry registry = builtins();
  Simulation<2> sim(loadScene(kScenes + "pendulum_2d.json", {{"time.dt", "0.03333333333333333"}}), registry);
  const double start = sim.step().at("total_energy");  // the first step's, then none above it
  const double swing = 3 * kG * (2.5 / 3) * (1 - std::cos(5 * kPi / 180));
  double worstRise = -1e300, end = start;
  while (!sim.finished()) {
    end = sim.step().at("total_energy");
    worstRise = std::max(worstRise, end - start);
  }
  std::cout << "[measured] pendulum_2d dt=1/30 largest energy rise " << worstRise << " J, loss over 10 s "
            << start - end << " J (swing " << swing << " J)\n";
  EXPECT_LT(worstRise, 1e-3 * swing);  // pre-stabilization must not pump energy in
}

TEST(Articulation2d, ChainStaysJoinedWithoutGainingEnergyOnAnyThreadCount) {
  const Registry registry = builtins();
  const SceneSpec scene = loadScene(kScenes + "chain_2d.json");
  Simulation<2> one(scene, registry, 1), two(scene, registry, 2);
  const double scale = 20 * 0.1 * kG * 2.0;  // the chain's weight times its length
  double worstError = 0, worstRise = -1e300;
  while (!one.finished()) {
    const auto& diag = one.step();
    two.step();
    worstError = std::max(worstError, diag.at("joint_error_max"));
    worstRise = std::max(worstRise, diag.at("total_energy"));  // it starts at 0 (all links at y = 0, at rest)
  }
  std::cout << "[measured] chain_2d joint_error_max " << worstError << " m, energy rise " << worstRise << " J\n";
  EXPECT_LT(worstError, 1e-4 * 0.1);
  EXPECT_LT(worstRise, 1e-3 * scale);
  EXPECT_EQ(stateHash(one.world()), stateHash(two.world()));
  EXPECT_LT(bodyNamed(one, "link19").x.y(), -1.0);  // it fell
}

TEST(Articulation2d, GlobalAndPairwisePostStabilizationAgreeAtConvergence) {
  const Registry registry = builtins();
  auto run = [&](const char* post) {
    SceneSpec scene = loadScene(kScenes + "chain_2d.json",
                                {{"entities.solver.articulation.post_stabilization", post},
                                 {"entities.solver.articulation.post_iterations", "100000"},
                                 {"entities.solver.articulation.post_tolerance", "1e-14"},
                                 {"entities.solver.articulation.pre_tolerance", "1e-13"},
                                 {"time.end", "0.1"}});
    auto sim = std::make_unique<Simulation<2>>(scene, registry);
    int k = 0;
    for (auto& b : sim->world().pool<RigidBody<2>>().components()) {  // work for the projections
      b.setOmega(Eigen::Matrix<double, 1, 1>(std::sin(1.0 + k)));
      b.v += Eigen::Vector2d(0.1 * std::cos(2.0 * k), 0.05 * k);
      ++k;
    }
    while (!sim->finished()) sim->step();
    std::vector<double> state;
    for (const auto& b : sim->world().pool<RigidBody<2>>().components())
      state.insert(state.end(), {b.x.x(), b.x.y(), b.v.x(), b.v.y(), b.L(0), b.orientation});
    return state;
  };
  const auto a = run("pairwise"), b = run("global");
  double worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::abs(a[i] - b[i]));
  std::cout << "[measured] chain_2d global vs pairwise largest state difference " << worst << "\n";
  EXPECT_LT(worst, 1e-8);
}

// A box on a frictionless slider along (cos 30, -sin 30): it slides as in free fall along the
// rail, s = g sin 30 t^2 / 2 (Step IV's x + dt v with the half-step velocity is exact for a
// constant acceleration), and does not turn.
TEST(Articulation2d, PrismaticJointSlidesAsInFreeFallAlongItsRail) {
  const Registry registry = builtins();
  const double c = std::cos(kPi / 6), s = std::sin(kPi / 6);
  Simulation<2> sim(parseScene(singleBody(R"({ "mass": 2, "angle": 0.3, "angular_velocity": 1 })",
                                          R"({ "type": "prismatic", "parent": "world", "anchor": [0, 0], "axis": [0.8660254037844386, -0.5] })",
                                          1.0, "[0, -9.81]"),
                               "slider.json"),
                    registry);
  double worst = 0, worstAngle = 0;
  while (!sim.finished()) {
    const auto& d = sim.step();
    worst = std::max(worst, d.at("joint_error_max"));
    worstAngle = std::max(worstAngle, d.at("joint_angle_error_max"));
  }
  const RigidBody<2>& b = bodyNamed(sim, "link");
  const Eigen::Vector2d axis(c, -s);
  const double slide = 0.5 * kG * s * 1.0;
  std::cout << "[measured] 2-D prismatic: slide " << b.x.dot(axis) << " m (free fall along the rail " << slide
            << " m), angle " << b.orientation << ", joint errors " << worst << " m, " << worstAngle << " rad\n";
  EXPECT_NEAR(b.x.dot(axis), slide, 1e-9);
  EXPECT_NEAR(b.x.dot(Eigen::Vector2d(s, c)), 0, 1e-9);  // on the rail
  EXPECT_NEAR(b.orientation, 0.3, 1e-9);  // the spin was taken away at the start, the angle kept
  EXPECT_LT(worst, 1e-9);
  EXPECT_LT(worstAngle, 1e-9);
}

// The slider of PrismaticJointSlidesAsInFreeFallAlongItsRail with slide limits [-0.1, 0.4] m:
// it slides down to 0.4 m and stops there, the total energy never above the start.
TEST(Articulation2d, SlideLimitsStopTheSlider) {
  const Registry registry = builtins();
  const Eigen::Vector2d axis(std::cos(kPi / 6), -std::sin(kPi / 6));
  Simulation<2> sim(parseScene(singleBody(R"({ "mass": 2 })",
                                          R"({ "type": "prismatic", "parent": "world", "anchor": [0, 0], "axis": [0.8660254037844386, -0.5], "slide_limits": [-0.1, 0.4] })",
                                          1.0, "[0, -9.81]"),
                               "slider.json"),
                    registry);
  double worst = 0, largest = -1e300, start = 0, rise = -1e300;
  while (!sim.finished()) {
    const auto& d = sim.step();
    worst = std::max(worst, d.at("joint_error_max"));
    if (start == 0) start = d.at("total_energy");
    rise = std::max(rise, d.at("total_energy") - start);
    largest = std::max(largest, bodyNamed(sim, "link").x.dot(axis));
  }
  const double slide = bodyNamed(sim, "link").x.dot(axis);
  std::cout << "[measured] 2-D slide limit 0.4 m: slide at 1 s " << slide << " m, largest " << largest
            << " m, energy rise " << rise << " J, joint_error_max " << worst << " m\n";
  EXPECT_NEAR(slide, 0.4, 1e-6);
  EXPECT_LT(largest, 0.4 + 1e-6);
  EXPECT_LT(rise, 1e-9);
  EXPECT_LT(worst, 1e-6);
}

// A link pinned at one end, no gravity, driven to 0.5 rad by PD: I a'' = kp (a* - a) - kd a',
// gains for zeta = 0.3 and w_n = 2 pi: overshoot exp(-pi zeta / sqrt(1 - zeta^2)) = 0.372.
TEST(Articulation2d, PdDriveOvershootsAsItsGainsPredict) {
  const Registry registry = builtins();
  const double I = 1.0 * (1.0 + 0.04 * 0.04) / 12 + 0.25;  // box 1 x 0.04, 1 kg, about its end
  const double wn = 2 * kPi, zeta = 0.3;
  const double kp = I * wn * wn, kd = 2 * zeta * wn * I;
  Simulation<2> sim(parseScene(singleBody(R"({ "mass": 1, "position": [0.5, 0] })",
                                          R"({ "type": "revolute", "parent": "world", "anchor": [0, 0], "pd": { "kp": )" +
                                              std::to_string(kp) + R"(, "kd": )" + std::to_string(kd) +
                                              R"(, "target": 0.5 } })",
                                          4.0),
                               "pd.json"),
                    registry);
  double peak = 0, settledAt = 0, worst = 0;
  while (!sim.finished()) {
    worst = std::max(worst, sim.step().at("joint_error_max"));
    const Eigen::Vector2d x = bodyNamed(sim, "link").x;
    const double angle = std::atan2(x.y(), x.x());
    peak = std::max(peak, angle);
    if (std::abs(angle - 0.5) > 0.02 * 0.5) settledAt = sim.time();
  }
  const double overshoot = (peak - 0.5) / 0.5, predicted = std::exp(-kPi * zeta / std::sqrt(1 - zeta * zeta));
  std::cout << "[measured] 2-D PD overshoot " << overshoot << " (predicted " << predicted << "), settled (2 %) at "
            << settledAt << " s\n";
  EXPECT_NEAR(overshoot, predicted, 0.03);  // explicit PD at dt w_n = 0.026: a few % of the overshoot
  EXPECT_LT(settledAt, 3.0);                // 4 / (zeta w_n) = 2.1 s
  EXPECT_LT(worst, 1e-8);
}

TEST(Articulation2d, PinLimitsStopTheSwing) {
  const Registry registry = builtins();
  // A rod hanging from a pin, kicked to swing about 1 rad each way; limits at +-0.3 rad.
  Simulation<2> sim(parseScene(R"({ "dimension": 2, "time": { "dt": 0.004166666666666667, "end": 2.0 },
    "gravity": [0, -9.81], "entities": [
    { "name": "rod", "shape": { "type": "box", "half_extents": [0.02, 0.5] },
      "rigid_body": { "mass": 1, "position": [0, -0.5], "velocity": [2, 0], "angular_velocity": 4 },
      "joint": { "type": "revolute", "parent": "world", "anchor": [0, 0], "limits": [-0.3, 0.3] } } ] })",
                               "limits.json"),
                    registry);
  double largest = 0, smallest = 0, worst = 0;
  while (!sim.finished()) {
    worst = std::max(worst, sim.step().at("joint_error_max"));
    const Eigen::Vector2d x = bodyNamed(sim, "rod").x;
    const double a = std::atan2(x.x(), -x.y());
    largest = std::max(largest, a), smallest = std::min(smallest, a);
  }
  EXPECT_NEAR(largest, 0.3, 1e-6);
  EXPECT_GT(smallest, -0.3 - 1e-6);
  EXPECT_LT(worst, 1e-8);
}

// Checkpoint at step 100 and resume (the CLI): the straight and resumed runs end bitwise equal.
TEST(Articulation2d, CheckpointResumesBitwise) { test::expectResumeMatchesStraightRun("chain_2d.json", "0.6"); }

TEST(Articulation2d, BadJointsAreRefusedAtTheirJsonPath) {
  const Registry registry = builtins();
  auto refuse = [&](const std::string& joint, const std::string& path, const std::string& extra = "") {
    const std::string text = R"({ "dimension": 2, "time": { "dt": 0.01, "end": 0.1 }, "entities": [
      { "name": "floor", "rigid_body": { "static": true } },
      { "name": "a", "shape": { "type": "disk", "radius": 0.1 }, "rigid_body": { "mass": 1 } },
      { "name": "b", "shape": { "type": "disk", "radius": 0.1 }, "rigid_body": { "mass": 1, "position": [1, 0] } },
      { "name": "j", "joint": )" + joint + "}" + extra + "] }";
    test::expectRefusedAt<2>(registry, text, path);
  };
  // Joints that need a third dimension.
  refuse(R"({ "type": "spherical", "parent": "a", "child": "b", "anchor": [0, 0] })", "entities[3].joint.type");
  refuse(R"({ "type": "universal", "parent": "a", "child": "b", "anchor": [0, 0] })", "entities[3].joint.type");
  refuse(R"({ "type": "revolute", "parent": "a", "child": "b", "anchor": [0, 0, 0] })", "entities[3].joint.anchor");
  refuse(R"({ "type": "revolute", "parent": "a", "child": "nobody", "anchor": [0, 0] })", "entities[3].joint.child");
  refuse(R"({ "type": "revolute", "parent": "ghost", "child": "a", "anchor": [0, 0] })", "entities[3].joint.parent");
  refuse(R"({ "type": "fixed", "parent": "world", "child": "floor", "anchor": [0, 0] })", "entities[3].joint");
  refuse(R"({ "type": "prismatic", "parent": "a", "child": "b", "anchor": [0, 0] })", "entities[3].joint.axis");
  refuse(R"({ "type": "prismatic", "parent": "a", "child": "b", "anchor": [0, 0], "axis": [0, 0] })",
         "entities[3].joint.axis");
  refuse(R"({ "type": "prismatic", "parent": "a", "child": "b", "anchor": [0, 0], "axis": [1, 0], "limits": [-1, 1] })",
         "entities[3].joint.limits");
  refuse(R"({ "type": "fixed", "parent": "a", "child": "b", "parent_frame": { "angle": 0 } })", "entities[3].joint.child_frame");
  refuse(R"({ "type": "revolute", "parent": "a", "child": "b", "anchor": [0, 0], "limits": [1, -1] })",
         "entities[3].joint.limits");
  refuse(R"({ "type": "fixed", "parent": "a", "child": "b", "anchor": [0, 0], "pd": { "kp": 1, "target": 0 } })",
         "entities[3].joint.pd");
  // Two pins hold "a" to the world at two points: one of the second's two rows repeats the first's.
  refuse(R"({ "type": "revolute", "parent": "world", "child": "a", "anchor": [0, 0] })", "entities[4].joint", R"(,
      { "name": "k", "joint": { "type": "revolute", "parent": "world", "child": "a", "anchor": [0.5, 0] } })");
  // A second fixed joint between the same bodies closes a loop of fixed joints.
  refuse(R"({ "type": "fixed", "parent": "a", "child": "b", "anchor": [0.5, 0] })", "entities[4].joint", R"(,
      { "name": "k", "joint": { "type": "fixed", "parent": "b", "child": "a", "anchor": [0.5, 0] } })");
  refuse(R"({ "type": "revolute", "parent": "a", "child": "b", "anchor": [0.5, 0] })", "entities[5].articulation", R"(,
      { "name": "s1", "articulation": {} }, { "name": "s2", "articulation": {} })");
}

// A planar ring of pins is a mechanism in the plane (in 3-D the same ring of parallel hinges
// repeats rows and is refused): a four-bar linkage on the world (a parallelogram) is accepted
// and stays closed. Pairwise pre-stabilization's Newton converges slowly where the parallelogram
// nears its change point (its rows nearly dependent): 7.2e-6 m left at 0.92 s with 20 sweeps,
// 1.0e-6 m with 200; the global Newton closes it to 1e-10 m.
TEST(Articulation2d, FourBarLinkageIsAcceptedAndStaysClosed) {
  const Registry registry = builtins();
  const std::string scene = R"({ "dimension": 2, "time": { "dt": 0.004166666666666667, "end": 1.0 },
    "gravity": [0, -9.81], "entities": [
    { "name": "crank", "shape": { "type": "box", "half_extents": [0.02, 0.25] },
      "rigid_body": { "mass": 1, "position": [0, 0.25] },
      "joint": { "type": "revolute", "parent": "world", "anchor": [0, 0] } },
    { "name": "coupler", "shape": { "type": "box", "half_extents": [0.5, 0.02] },
      "rigid_body": { "mass": 1, "position": [0.5, 0.5], "velocity": [1, 0] },
      "joint": { "type": "revolute", "parent": "crank", "anchor": [0, 0.5] } },
    { "name": "rocker", "shape": { "type": "box", "half_extents": [0.02, 0.25] },
      "rigid_body": { "mass": 1, "position": [1, 0.25] },
      "joint": { "type": "revolute", "parent": "coupler", "anchor": [1, 0.5] } },
    { "name": "ground_pin", "joint": { "type": "revolute", "parent": "world", "child": "rocker", "anchor": [1, 0] } } ] })";
  auto worstError = [&](const char* pre) {
    Simulation<2> sim(parseScene(scene, "four_bar.json", {{"entities.ground_pin.articulation.pre_stabilization", pre}}),
                      registry);
    double worst = 0;
    while (!sim.finished()) worst = std::max(worst, sim.step().at("joint_error_max"));
    EXPECT_GT(std::abs(bodyNamed(sim, "crank").orientation), 0.1);  // it moved
    return worst;
  };
  const double pairwise = worstError("pairwise"), global = worstError("global");
  std::cout << "[measured] 2-D four-bar linkage joint_error_max " << pairwise << " m (pairwise), " << global
            << " m (global)\n";
  EXPECT_LT(pairwise, 1e-4);
  EXPECT_LT(global, 1e-8);
}

// chain_2d given colliders and a ground 1.5 m down: it falls, whips onto the ground and lies
// there. Contact works with the joints as in 3-D (rounds of pre-stabilization within Step III,
// the jointed push-out solve, Step V's joint-and-contact solve): without that coupling the
// impacts opened the joints by 6.1 mm.
TEST(Articulation2d, ChainDroppedOnTheGroundKeepsItsJointsClosedOnAnyThreadCount) {
  const Registry registry = builtins();
  std::ifstream in(kScenes + "chain_2d.json");
  std::string line, text;
  while (std::getline(in, line))
    if (line.rfind("//", 0) != 0) text += line + "\n";
  nlohmann::json scene = nlohmann::json::parse(text);
  for (auto& e : scene["entities"])
    if (e.contains("shape")) e["collider"] = nlohmann::json::object();
  scene["entities"].push_back({{"name", "ground"},
                               {"shape", {{"type", "plane"}, {"normal", {0, 1}}}},
                               {"rigid_body", {{"static", true}, {"position", {0, -1.5}}}},
                               {"collider", nlohmann::json::object()}});
  scene["time"]["end"] = 2.0;
  scene.erase("checks");
  const SceneSpec spec = parseScene(scene.dump(), "chain_2d_ground.json");
  Simulation<2> one(spec, registry, 1), two(spec, registry, 2);
  double worst = 0, deepest = 0;
  while (!one.finished()) {
    const auto& diag = one.step();
    two.step();
    worst = std::max(worst, diag.at("joint_error_max"));
    if (one.time() > 1.0) deepest = std::max(deepest, diag.at("max_penetration"));
  }
  double lowest = 1e300;
  for (int k = 0; k < 20; ++k) lowest = std::min(lowest, bodyNamed(one, "link" + std::to_string(k)).x.y());
  std::cout << "[measured] chain_2d on the ground: joint_error_max " << worst << " m, max_penetration after 1 s "
            << deepest << " m, lowest link centre " << lowest << " m\n";
  EXPECT_LT(worst, 1e-6);
  EXPECT_LT(deepest, 5e-3);
  EXPECT_GT(lowest, -1.5);  // on the ground, not through it
  EXPECT_LT(lowest, -1.45);  // it reached the ground
  EXPECT_EQ(stateHash(one.world()), stateHash(two.world()));
}

// Rigid collisions, contact and friction (thesis Ch. 2.3, 4.2-4.6, App. B), checked on
// the scene files against closed forms: Coulomb sliding and sticking on an incline, rolling in
// 2-D, restitution apex ratios, Newton's cradle, a kinematic elevator, frame-rate stacking, and
// the energy rules of Sec. 2.3.2 (collision impulses and the second contact step never add
// kinetic energy; total energy never rises by more than 0.1 %).
#include <gtest/gtest.h>

#include "support/scenes.h"
#include "support/unit_cube_obj.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "components/rigid_body.h"
#include "scenarios/simulation.h"

using namespace monolith;

namespace {
using test::bodyNamed;
using test::builtins;
using test::kScenes;

const double kG = 9.81;

std::string num(double x) {
  std::ostringstream out;
  out.precision(17);
  out << x;
  return out.str();
}

// Watches the energy rules at every step of a scene.
struct EnergyWatch {
  double initialTotal = 0, worstRise = 0, worstCollisionGain = 0, worstContactGain = 0;
  bool first = true;
  void observe(const std::map<std::string, double>& diag) {
    const double total = diag.at("total_energy");
    if (first) initialTotal = total, first = false;
    worstRise = std::max(worstRise, total - initialTotal);
    if (diag.count("collision_energy_change"))
      worstCollisionGain = std::max(worstCollisionGain, diag.at("collision_energy_change"));
    if (diag.count("velocity_contact_energy_change"))
      worstContactGain = std::max(worstContactGain, diag.at("velocity_contact_energy_change"));
  }
  // The initial total is measured after the first step; scale: |initial| or the kinetic energy.
  void expectNoGain(double scale) const {
    EXPECT_LE(worstCollisionGain, 1e-12) << "collision impulses added kinetic energy";
    EXPECT_LE(worstContactGain, 1e-12) << "the second contact step added kinetic energy";
    EXPECT_LE(worstRise, 1e-3 * scale) << "total energy rose above its initial value";
  }
};

// Runs a scene to its end under the energy watch; returns the deepest overlap of a contact pair
// after push-out over the smaller body's size, over all steps.
template <int d>
double runToEndWatching(Simulation<d>& sim, EnergyWatch& watch) {
  double worst = 0;
  while (!sim.finished()) {
    const auto& diag = sim.step();
    watch.observe(diag);
    worst = std::max(worst, diag.at("max_penetration_ratio"));
  }
  return worst;
}

// Runs a scene to its end, expecting no energy gain; returns its deepest overlap (as above).
template <int d = 3>
double deepestOverlapWithoutEnergyGain(const SceneSpec& scene, const Registry& registry) {
  Simulation<d> sim(scene, registry);
  EnergyWatch watch;
  const double worst = runToEndWatching(sim, watch);
  watch.expectNoGain(std::abs(watch.initialTotal));
  return worst;
}

template <int d>
Eigen::Matrix<double, d, 1> positionOf(Simulation<d>& sim, const std::string& name) {
  return sim.world().template get<RigidBody<d>>(*sim.world().find(name))->x;
}

double slideDistance(double dt, double mu, double T, EnergyWatch* watch = nullptr) {
  const Registry registry = builtins();
  const SceneSpec scene = loadScene(kScenes + "incline_friction.json",
                                    {{"time.dt", num(dt)}, {"time.end", num(T)},
                                     {"entities.cube.collider.friction", num(mu)}});
  Simulation<3> sim(scene, registry);
  const Eigen::Vector3d x0 = positionOf(sim, "cube");
  const double theta = M_PI / 6;
  const Eigen::Vector3d down(std::cos(theta), -std::sin(theta), 0);
  while (!sim.finished()) {
    const auto& diag = sim.step();
    if (watch) watch->observe(diag);
  }
  EXPECT_NEAR(sim.time(), T, 1e-9);
  return (positionOf(sim, "cube") - x0).dot(down);
}

}  // namespace

TEST(InclineFriction, SlidingCubeFollowsCoulombLawAtFrameRateAndFine) {
  const double theta = M_PI / 6, mu = 0.3, T = 2.0;
  const double exact = 0.5 * kG * (std::sin(theta) - mu * std::cos(theta)) * T * T;
  for (double dt : {1.0 / 30, 1.0 / 240}) {
    EnergyWatch watch;
    const double s = slideDistance(dt, mu, T, &watch);
    EXPECT_NEAR(s / exact, 1.0, 0.01) << "dt = " << dt << ": s = " << s << ", exact " << exact;
    watch.expectNoGain(std::abs(watch.initialTotal) + 1);
  }
}

TEST(InclineFriction, StickingCubeDriftsLessThanAMillimetreIn5s) {
  EnergyWatch watch;
  const double s = slideDistance(1.0 / 30, 0.7, 5.0, &watch);
  EXPECT_LT(std::abs(s), 1e-3);
  watch.expectNoGain(std::abs(watch.initialTotal) + 1);
}

TEST(InclineRoll2D, DiskRollsWithoutSlipping) {
  const Registry registry = builtins();
  const SceneSpec scene = loadScene(kScenes + "incline_roll_2d.json");
  Simulation<2> sim(scene, registry);
  const Eigen::Vector2d x0 = positionOf(sim, "disk");
  const double theta = M_PI / 6;
  const Eigen::Vector2d down(std::cos(theta), -std::sin(theta));
  EnergyWatch watch;
  while (!sim.finished()) watch.observe(sim.step());
  const double T = sim.time();
  const double a = 2.0 / 3.0 * kG * std::sin(theta);
  const double s = (positionOf(sim, "disk") - x0).dot(down);
  EXPECT_NEAR(s / (0.5 * a * T * T), 1.0, 0.02);
  // Rolling: the contact point does not slip, v = -w r (clockwise spin when moving down-slope).
  const RigidBody<2>& disk = bodyNamed(sim, "disk");
  EXPECT_NEAR(disk.v.dot(down), -disk.omega()(0) * 0.5, 0.02 * disk.v.norm());
  watch.expectNoGain(std::abs(watch.initialTotal) + 1);
}

namespace {
// Apex heights (of the sphere's bottom) after each bounce.
std::vector<double> apexes(double e, double T, EnergyWatch& watch, std::vector<double>* heights = nullptr) {
  const Registry registry = builtins();
  const SceneSpec scene = loadScene(kScenes + "bounce.json", {{"entities.ball.collider.restitution", num(e)},
                                                               {"time.end", num(T)}});
  Simulation<3> sim(scene, registry);
  std::vector<double> out;
  double previousVy = 0;
  while (!sim.finished()) {
    watch.observe(sim.step());
    const RigidBody<3>& ball = bodyNamed(sim, "ball");
    if (heights) heights->push_back(ball.x.y() - 0.5);
    if (previousVy > 0 && ball.v.y() <= 0) out.push_back(ball.x.y() - 0.5);
    previousVy = ball.v.y();
  }
  return out;
}
}  // namespace

TEST(Bounce, ApexRatiosAreRestitutionSquared) {
  for (double e : {0.5, 0.9}) {
    EnergyWatch watch;
    const std::vector<double> h = apexes(e, 2.5, watch);
    ASSERT_GE(h.size(), 2u) << "e = " << e;
    EXPECT_NEAR(h[0] / 1.0 / (e * e), 1.0, 0.02) << "first bounce, e = " << e;
    EXPECT_NEAR(h[1] / h[0] / (e * e), 1.0, 0.02) << "second bounce, e = " << e;
    watch.expectNoGain(std::abs(watch.initialTotal));
  }
}

TEST(Bounce, InelasticBallStopsInOneStepWithoutJitter) {
  EnergyWatch watch;
  std::vector<double> heights;
  apexes(0.0, 1.0, watch, &heights);
  // Free fall from 1 m takes sqrt(2/g) = 0.4515 s; from the first step that touches on, the
  // height stays put to push-out tolerance (no bounce, no jitter).
  const int touch = static_cast<int>(std::ceil(std::sqrt(2.0 / kG) / 0.0005)) + 2;
  ASSERT_LT(touch, static_cast<int>(heights.size()));
  double lo = 1e9, hi = -1e9;
  for (std::size_t n = touch; n < heights.size(); ++n) lo = std::min(lo, heights[n]), hi = std::max(hi, heights[n]);
  EXPECT_LT(hi - lo, 1e-4) << "jitter after landing";
  EXPECT_LT(std::abs(hi), 1e-2) << "resting height of the bottom";
  watch.expectNoGain(std::abs(watch.initialTotal));
}

TEST(NewtonsCradle, FarSphereLeavesWithTheIncomingSpeed) {
  const Registry registry = builtins();
  Simulation<3> sim(loadScene(kScenes + "newtons_cradle.json"), registry);
  EnergyWatch watch;
  for (int n = 0; n < 20; ++n) watch.observe(sim.step());
  EXPECT_GE(bodyNamed(sim, "far").v.x(), 0.95);
  for (const char* name : {"striker", "b1", "b2", "b3"}) EXPECT_LE(bodyNamed(sim, name).v.norm(), 0.05) << name;
  watch.expectNoGain(1.0);
}

TEST(Elevator, BoxRidesTheKinematicPlatform) {
  const Registry registry = builtins();
  Simulation<3> sim(loadScene(kScenes + "elevator.json"), registry);
  double worst = 0, worstCollisionGain = -1, worstContactGain = -1;
  int frameSteps = 0;
  while (!sim.finished()) {
    // No world-frame energy check: the platform lifts the box. The clamp bounds the impulses in
    // the platform's frame (Sec. 2.3.2), so there neither stage may add kinetic energy.
    const auto& diag = sim.step();
    if (diag.count("collision_energy_change_kinematic_frame") && diag.count("velocity_contact_energy_change_kinematic_frame")) {
      ++frameSteps;
      worstCollisionGain = std::max(worstCollisionGain, diag.at("collision_energy_change_kinematic_frame"));
      worstContactGain = std::max(worstContactGain, diag.at("velocity_contact_energy_change_kinematic_frame"));
    }
    if (sim.time() > 1.0) worst = std::max(worst, (bodyNamed(sim, "box").v - bodyNamed(sim, "platform").v).norm());
  }
  EXPECT_EQ(frameSteps, sim.stepsDone());
  EXPECT_LE(worstCollisionGain, 1e-12) << "collision impulses added kinetic energy in the platform's frame";
  EXPECT_LE(worstContactGain, 1e-12) << "the second contact step added kinetic energy in the platform's frame";
  EXPECT_LT(worst, 1e-3);
  // It went up with the platform (2.5 s at 1 m/s) and sits on it.
  EXPECT_NEAR(positionOf(sim, "box").y() - positionOf(sim, "platform").y(), 0.75, 0.01);
  EXPECT_NEAR(positionOf(sim, "platform").y(), 2.5, 1e-9);
}

namespace {

// Runs a pyramid scene to its end: every box within 0.05 of its start, kinetic energy < 1e-3,
// no energy gain.
template <int d>
void expectPyramidStands(const std::string& sceneName, double keBound = 1e-3, double riseBound = -1,
                         double driftBound = 0.05, const std::vector<std::pair<std::string, std::string>>& overrides = {}) {
  const Registry registry = builtins();
  Simulation<d> sim(loadScene(kScenes + sceneName, overrides), registry);
  ASSERT_NEAR(sim.scene().dt, 1.0 / 30, 1e-15);
  std::vector<Eigen::Matrix<double, d, 1>> start;
  for (const auto& b : sim.world().template pool<RigidBody<d>>().components()) start.push_back(b.x);
  EnergyWatch watch;
  while (!sim.finished()) watch.observe(sim.step());
  double drift = 0, ke = 0;
  const auto& bodies = sim.world().template pool<RigidBody<d>>().components();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    drift = std::max(drift, (bodies[i].x - start[i]).norm());
    ke += bodies[i].translationalKineticEnergy() + bodies[i].rotationalKineticEnergy();
  }
  std::printf("%s: max drift %.2e, final KE %.2e\n", sceneName.c_str(), drift, ke);
  EXPECT_LT(drift, driftBound);
  EXPECT_LT(ke, keBound);
  watch.expectNoGain(std::abs(watch.initialTotal));
  if (riseBound >= 0) {
    EXPECT_LT(watch.worstRise, riseBound);
  }
}

}  // namespace

TEST(Pyramid, TenLayersStandAtOneStepPerFrame) { expectPyramidStands<3>("pyramid_10.json"); }

TEST(Pyramid, TenLayersStandAtOneStepPerFrameIn2D) {
  // Two points per box pair, one friction direction: the shock propagation's joint solves of a
  // box against the two below converge more slowly than in 3-D. With their 10 sweeps (the
  // default before 2026-11-26) and 2 level passes this pyramid kept 5.9e-5 J of kinetic energy
  // and its total energy rose steadily, 0.70 J over the 10 s (20 layers: 8e-3 J and 11 J), inside
  // the issue's bounds but far from rest; with 40 sweeps 4e-12 J and 2.2e-4 J (measured). The
  // tighter bounds below tell the two apart.
  expectPyramidStands<2>("pyramid_2d_10.json", 1e-8, 0.01);
}

namespace {
// One contact iteration of one level pass and one shock propagation pass (the git history of docs/benchmarks.md
// ("A short schedule")), with the manifold solves finished exactly (manifold_polish.h).
const std::vector<std::pair<std::string, std::string>> kShortScheduleExact = {
    {"solvers.contact.contact_iterations", "1"},
    {"solvers.contact.contact_level_iterations", "1"},
    {"solvers.contact.shock_level_iterations", "1"},
    {"solvers.contact.exact_manifold_finish", "true"}};
}  // namespace

TEST(Pyramid, TwentyLayersStandExactlyAtRestOnAShortScheduleWithExactManifoldSolves) {
  // Sweeps alone on this schedule leave 1.6e-6 of drift and 3e-13 J after 10 s; finished exactly,
  // every box is at rest to rounding (measured 3.7e-15 and 6e-29 J) at half the cost per step.
  // The sweeps-only figures are above these bounds, so the test fails if the finish never applies.
  expectPyramidStands<3>("pyramid_20.json", 1e-20, -1, 1e-10, kShortScheduleExact);
}

TEST(Pyramid, TenLayersIn2DStandExactlyAtRestWithExactManifoldSolves) {
  expectPyramidStands<2>("pyramid_2d_10.json", 1e-20, 1e-9, 1e-10, kShortScheduleExact);
}

TEST(BoxStackScatter, PenetrationStaysBelowOnePercentOfTheSmallerBody) {
  // On the thesis's schedule (measured 0.16 %). The default short schedule lets each landing
  // box close its gap in the one contact pass, so the column of six landing boxes is pressed
  // together harder than by a pass that stops every box where it is: 1.02 % for one step
  // (0.65 % without closing gaps; docs/benchmarks_rigid_contact.md), under the 1.5 % bound below.
  const Registry registry = builtins();
  for (const char* schedule : {"thesis", "short"}) {
    SCOPED_TRACE(schedule);
    Simulation<3> sim(loadScene(kScenes + "box_stack_scatter.json", {{"solvers.contact.schedule", schedule}}),
                      registry);
    EnergyWatch watch;
    EXPECT_LE(runToEndWatching(sim, watch), std::string(schedule) == "thesis" ? 0.01 : 0.015);
    // The boulder reached the stack and scattered it: the top box is no longer on top.
    EXPECT_LT(positionOf(sim, "stack_5").y(), 3.0);
    watch.expectNoGain(std::abs(watch.initialTotal));
  }
}

namespace {

// Steps a scene on 1 and 2 threads side by side and asserts bitwise equal rigid states.
void expectSameStateOnOneAndTwoThreads(const SceneSpec& scene) {
  const Registry registry = builtins();
  Simulation<3> one(scene, registry, 1), two(scene, registry, 2);
  while (!one.finished()) one.step(), two.step();
  const auto& a = one.world().pool<RigidBody<3>>().components();
  const auto& b = two.world().pool<RigidBody<3>>().components();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(0, std::memcmp(a[i].x.data(), b[i].x.data(), sizeof(double) * 3)) << i;
    ASSERT_EQ(0, std::memcmp(a[i].v.data(), b[i].v.data(), sizeof(double) * 3)) << i;
    ASSERT_EQ(0, std::memcmp(a[i].L.data(), b[i].L.data(), sizeof(double) * 3)) << i;
    ASSERT_EQ(0, std::memcmp(a[i].orientation.coeffs().data(), b[i].orientation.coeffs().data(), sizeof(double) * 4));
  }
}
void expectSameStateOnOneAndTwoThreads(const std::string& sceneName, const std::string& end,
                                       std::vector<std::pair<std::string, std::string>> overrides = {}) {
  overrides.emplace_back("time.end", end);
  expectSameStateOnOneAndTwoThreads(loadScene(kScenes + sceneName, overrides));
}

}  // namespace

TEST(ContactDeterminism, SameStateOnOneAndTwoThreads) {
  // Many islands, handed to the threads whole; the pile's push-out plans (up to 250 bodies) are
  // recorded in chunks, each running while the next is recorded (push_out_rounds.h): 42 chunks
  // start by 0.5 s.
  expectSameStateOnOneAndTwoThreads("pour_spheres_250.json", "0.5");
}

TEST(ContactDeterminism, OneIslandSweptOnTwoThreadsGivesTheOneThreadState) {
  // One island of 55 boxes: its pair updates, joint solves and freezes run as ordered tasks on
  // both threads (systems/contact_workspace.h), and must give bitwise the sequential state.
  expectSameStateOnOneAndTwoThreads("pyramid_10.json", "1");
}

TEST(ContactDeterminism, ABoxDroppedOnARestingPyramidGivesTheSameStateOnOneAndTwoThreads) {
  // On the short exact schedule the resting pyramid's collision stage applies no impulse, so on
  // two threads its first collision sweep runs every pair update at once, unapplied
  // (ContactWorkspace::speculativeCollisionSweep). The box landing at about 0.5 s gives that
  // sweep impulses to apply: from the first, the rest of it must run as the ordered sweep does.
  std::ifstream file(kScenes + "pyramid_10.json");
  std::stringstream text;
  text << file.rdbuf();
  std::string scene = text.str();
  // The box is the last body, so its pairs come last in the sweep: most updates are taken first.
  const std::size_t at = scene.rfind(']');
  ASSERT_NE(at, std::string::npos);
  scene.insert(at, R"(,
  {"name": "dropped", "shape": {"type": "box", "half_extents": [0.4, 0.4, 0.4]}, "rigid_body": {"mass": 2.0,
   "position": [0.3, 11.5, 0.1]}, "collider": {"restitution": 0.3, "friction": 0.5}}
)");
  auto overrides = kShortScheduleExact;
  overrides.emplace_back("time.end", "1");
  expectSameStateOnOneAndTwoThreads(parseScene(scene, "pyramid_10_dropped.json", overrides));
}

TEST(ContactDeterminism, RandomDropsGiveTheSameStateOnOneAndTwoThreads) {
  // Needles, slabs, hulls and fast throws: swept collisions, push-out rounds and the
  // rotational-energy clamp on the way.
  expectSameStateOnOneAndTwoThreads("random_drop_186.json", "3", {});
  expectSameStateOnOneAndTwoThreads("random_drop_39.json", "3", {});
  expectSameStateOnOneAndTwoThreads("random_drop_142.json", "3", {});  // push-out's tied levels
}

TEST(ContactDeterminism, ExactManifoldSolvesGiveTheSameStateOnOneAndTwoThreads) {
  expectSameStateOnOneAndTwoThreads("mixed_pile.json", "1.5", {{"solvers.contact.exact_manifold_finish", "true"}});
}

TEST(MixedPile, EveryShapeSettlesWithoutEnergyGainOrDeepOverlap) {
  // Boxes, spheres, capsules, cylinders and convex octahedra (40 bodies) dropped with spins into
  // a walled box, 4 s at dt = 1/60: every 3-D shape pair of the narrow phase in a settling pile.
  // Before the exact penetration depths of cylinder and hull pairs (penetration_axis.cpp) and the
  // capsule-end rim contacts, the deepest overlap reached 1.34 % of a body's size and the pile
  // still had 0.099 J of kinetic energy at the end; now 0.28 % and 0.0037 J (docs/benchmarks.md).
  // The thesis's schedule, on which these figures were measured (the default short schedule:
  // MixedPile.ExactManifoldSolvesSettleItWithoutEnergyGain below).
  const Registry registry = builtins();
  Simulation<3> sim(loadScene(kScenes + "mixed_pile.json", {{"solvers.contact.schedule", "thesis"}}), registry);
  EnergyWatch watch;
  // The deepest overlap after any step, over every pair of the broad phase (before 2026-11-26
  // only pairs Step II had processed were measured, 0.28 % here). Measured that way it is 1.28 %
  // (steps 149-167: a body wedged between two static walls and a neighbour); over 8 runs with
  // dt and gravity changed by 1-3 % it was 0.20-1.28 %, and 0.47-1.49 % with the thesis's
  // push-out (the git history of docs/benchmarks.md ("Overlaps no stage saw")). With the pairs also found again
  // where the impulses sent the bodies (growPairs), 0.28 %, and 0.17-0.79 % over those 8 runs;
  // with 6 push-out passes 0.10 % and 0.01-0.36 %.
  EXPECT_LE(runToEndWatching(sim, watch), 0.01);
  // Settled: the energy left at t = 4 s is a snapshot of a chaotic pile, in which a sphere or
  // cylinder may still be rolling off it (no rolling resistance). Over 16 runs with dt and
  // gravity changed by 1-3 % (the git history of docs/benchmarks.md ("Swept collisions")) it was 0.002-0.17 J, and
  // above the 0.02 J this test once asserted in 3 of them -- 1 in 8 for the build that chose
  // that bound too. 0.5 J is 0.17 % of the 286 J the pile starts with.
  double ke = 0;
  for (const auto& b : sim.world().pool<RigidBody<3>>().components())
    ke += b.translationalKineticEnergy() + b.rotationalKineticEnergy();
  EXPECT_LT(ke, 0.5) << "the pile should have settled (it starts with 286 J of total energy)";
  watch.expectNoGain(std::abs(watch.initialTotal));
}

TEST(MixedPile, ExactManifoldSolvesSettleItWithoutEnergyGain) {
  // The same pile with the manifold solves finished exactly: edge, rim and sliding contacts of
  // every shape pair, where spurious impulses of sliding friction could feed energy in (the
  // finish's energy test). The pile is chaotic: a single run's deepest overlap moves by factors
  // under any change of rounding (0.005 % when this test was written, 0.40 % on the build before
  // shock propagation's friction changed), so the scene and four variants with gravity changed
  // by up to 1 %: the median deepest overlap under 1 %, none over the issue's 5 % (measured
  // 2026-11-28: 0.03-0.42 %, median 0.25 %).
  const Registry registry = builtins();
  std::vector<double> deepest;
  for (const char* g : {"[0, -9.81, 0]", "[0, -9.71, 0]", "[0, -9.76, 0]", "[0, -9.86, 0]", "[0, -9.91, 0]"}) {
    Simulation<3> sim(
        loadScene(kScenes + "mixed_pile.json", {{"solvers.contact.exact_manifold_finish", "true"}, {"gravity", g}}),
        registry);
    EnergyWatch watch;
    deepest.push_back(runToEndWatching(sim, watch));
    double ke = 0;
    for (const auto& b : sim.world().pool<RigidBody<3>>().components())
      ke += b.translationalKineticEnergy() + b.rotationalKineticEnergy();
    EXPECT_LT(ke, 0.5) << "gravity " << g;
    watch.expectNoGain(std::abs(watch.initialTotal));
  }
  std::sort(deepest.begin(), deepest.end());
  std::printf("mixed_pile with exact manifold solves, deepest overlap of 5 runs: %.3f %% to %.3f %%, median %.3f %%\n",
              100 * deepest.front(), 100 * deepest.back(), 100 * deepest[2]);
  EXPECT_LT(deepest[2], 0.01);
  EXPECT_LT(deepest.back(), 0.05);
}

TEST(RandomDrops, KeepTheEnergyRules) {
  // Bodies of random shape, size (needles and slabs too), mass, spin and speed thrown over a
  // plane (generate_contact_scenes.py --random SEED; 3 s each). Each of these seeds broke an
  // energy rule or sank more than 5 % of a body's size until 2026-11-27. The energy rules:
  //  - 39 gained 2.8 % of its total energy: contact (Step III) and push-out turned a spinning
  //    needle, and the post-collision momentum Step V starts from had more energy in the new
  //    orientation than in the old (now that momentum is scaled back to its time-n energy where
  //    it gained more than 5 %);
  //  - 186 and 204 gained 46 % and 0.6 % of their kinetic energy in Step V: its shock
  //    propagation clamped impulses against a frozen body in that body's frame, and the body
  //    moved (now in the world or the scene's kinematic frame).
  //  - 108 gained 1.1 % in Step V the same way.
  // The others sank deep, in push-out:
  //  - 108 and 186 41 % of a body's size into the ground and a wall: a light body wedged there
  //    also touched a heavy frozen one, which push-out weighted by its real mass, so the statics'
  //    fit kept the light body where it was (now every body of infinite mass in push-out weighs
  //    as the original code's unit static);
  //  - 37, 142 and 204 35 %, 44 % and 23 %: a slab sunk at both ends into the ground (or the
  //    ground and a wall) was turned out at its deepest point and in at the other end, solve
  //    after solve; in 142 a light box was also wedged between a wall and a heavy ball frozen
  //    on a level below. Now the rounds after the first take every overlapping point of a
  //    static and put the two bodies of each pair they work on on one level;
  //  - 40, 412 and 1316 60 %, 51 % and 50 % (after the change above): a needle, a small hull
  //    and a 1 cm box at the foot of a wall, pushed down by the wall's bottom face and up by the
  //    ground (the box slid through the wall's foot at ground level). Now a later round lets
  //    such a wall push through another face (escapeThroughBoxFace).
  //  - 1840 13.9 % (with walls reaching through the ground, grounded_box.h): a light box pressed
  //    into the ground by a heavy capsule lying on it, pushed up into the capsule by a later
  //    round, which was undone. Now a later round ties a focus body's overlapping dynamic pairs.
  // Deepest overlaps now (single chaotic runs): 37 0.05 %, 39 0.07 %, 40 0.09 %, 108 1.2 %,
  // 142 1.2 %, 186 2.0 %, 204 1.1 %, 412 0.6 %, 1316 0.09 %, 1840 2.0 %.
  const Registry registry = builtins();
  for (int seed : {37, 39, 40, 108, 142, 186, 204, 412, 1316, 1840}) {
    SCOPED_TRACE("random_drop_" + std::to_string(seed));
    const double deepest =
        deepestOverlapWithoutEnergyGain(loadScene(kScenes + "random_drop_" + std::to_string(seed) + ".json"), registry);
    EXPECT_LT(deepest, 0.05);
  }
}

TEST(RandomDrops, KeepTheEnergyRulesIn2D) {
  // The 2-D kind (generate_contact_scenes.py --random-2d SEED: boxes, disks and convex polygons
  // between two walls standing on a line). On be12a88 these sank 116 % and 107 % of a body's
  // size: 45 a thin body jammed under others, 216 a 93 g body at a wall's foot, pushed down by
  // the wall's bottom face and up by the ground (57.6 % still with the later rounds' ties and
  // static points alone; the face escape, escapeThroughBoxFace, takes it out). 255 and 459 are
  // jams of several bodies, which push-out's rounds left 62.7 % and 72.5 % deep for a step, each
  // body pushed into a neighbour the solve did not move (joint_push_out.h: all pushed at once).
  // 385 and 678 are jams that solve still left 37.2 % and 117 % deep: a needle wedged between a
  // disk in a corner and a second disk 3 cm off, which the jam kept fixed because it did not
  // overlap; and a jam that a pass pushed deep into a fixed partner. Now the jam takes in the
  // dynamic bodies within reach and grows between passes. 1421 is a small box wedged into a
  // corner by a disk, which the jam solve left 22 % deep while it asked the box for large turns
  // (JointPushOut.ATurnCostsWhatMovingItsFarthestPointWould).
  // Measured now: 1.8 %, 1.4 %, 1.7 %, 1.8 %, 1.9 %, 4.75 % and 1.3 % (single chaotic runs).
  const Registry registry = builtins();
  for (int seed : {45, 216, 255, 385, 459, 678, 1421}) {
    SCOPED_TRACE("random_drop_2d_" + std::to_string(seed));
    const double deepest = deepestOverlapWithoutEnergyGain<2>(
        loadScene(kScenes + "random_drop_2d_" + std::to_string(seed) + ".json"), registry);
    EXPECT_LT(deepest, 0.05);
  }
}

TEST(RandomDrops, KeepTheEnergyRulesIn2DOnTheShortSchedule) {
  // The short schedule (one contact sweep, one level iteration, one shock pass, the exact
  // finish) on 2-D drops 347 and 387. A first version of shock propagation's re-solve leaning
  // on the stage (2026-11-28) swept points that had only the exact finish's preparation, and
  // these two blew up (positions of 1e99 and 1e32 by steps 41 and 35; 10 of 600 seeds did).
  const Registry registry = builtins();
  for (int seed : {347, 387}) {
    SCOPED_TRACE("random_drop_2d_" + std::to_string(seed));
    const double deepest = deepestOverlapWithoutEnergyGain<2>(
        loadScene(kScenes + "random_drop_2d_" + std::to_string(seed) + ".json",
                  {{"solvers.contact.contact_iterations", "1"},
                   {"solvers.contact.contact_level_iterations", "1"},
                   {"solvers.contact.shock_level_iterations", "1"},
                   {"solvers.contact.exact_manifold_finish", "true"}}),
        registry);
    EXPECT_LT(deepest, 0.05);
  }
}

TEST(RandomDrops, HighMassRatioJamsSeparateOnTheShortSchedule) {
  // 2-D drops on the short schedule, each with a light body (60-200 g) jammed between bodies of
  // 10-48 kg and a wall or the ground: 1586, 2250 and 2512 went 10.1 %, 9.5 % and 8.8 % of a
  // body's size deep for a step. The joint push-out (joint_push_out.h) was asked to remove
  // overlaps below push-out's tolerance too; where a slab touched the ground and a fixed partner
  // above it by micrometres the program had no solution, its least-norm moves were metres long,
  // and the bound on a pass's largest move scaled every body's move down a hundredfold. Now it
  // separates what lies beyond the tolerance: 1.78 %, 1.74 % and 1.98 % (single chaotic runs).
  const Registry registry = builtins();
  for (int seed : {1586, 2250, 2512}) {
    SCOPED_TRACE("random_drop_2d_" + std::to_string(seed));
    const double deepest = deepestOverlapWithoutEnergyGain<2>(
        loadScene(kScenes + "random_drop_2d_" + std::to_string(seed) + ".json", {{"solvers.contact.schedule", "short"}}),
        registry);
    EXPECT_LT(deepest, 0.05);
  }
}

TEST(StepEnergyClamp, TakesBackWhatTheShortSchedulesFirstContactStepLifts) {
  // 2-D drops 261 and 736 on the short schedule. Without the step energy clamp a
  // spinning polygon that strikes the ground is turned upward by the one inelastic contact pass,
  // the position update lifts it by that velocity, and Step IV restores its fall and spin: the
  // total energy rose 0.95 % and 0.38 % in one step (measured; the rule is 0.1 %). With the
  // clamp (systems/step_energy_clamp.cpp) no step gains and nothing sinks deeper than 5 %.
  const Registry registry = builtins();
  for (int seed : {261, 736}) {
    SCOPED_TRACE("random_drop_2d_" + std::to_string(seed));
    const std::string file = kScenes + "random_drop_2d_" + std::to_string(seed) + ".json";
    // Gaps not closed, as the short schedule first was: closing them (ContactSettings::closeGaps)
    // removes both rises too (6e-14 and 0.012 %), the clamp stays as the bound on the whole step.
    Simulation<2> unclamped(loadScene(file, {{"solvers.contact.schedule", "short"},
                                             {"solvers.contact.close_gaps", "false"},
                                             {"solvers.contact.step_energy_clamp", "false"}}),
                            registry);
    EnergyWatch watch;
    runToEndWatching(unclamped, watch);
    EXPECT_GT(watch.worstRise, 2e-3 * std::abs(watch.initialTotal)) << "the case the clamp is for is gone";
    Simulation<2> clamped(loadScene(file, {{"solvers.contact.schedule", "short"}}), registry);
    EnergyWatch clampedWatch;
    const double deepest = runToEndWatching(clamped, clampedWatch);
    clampedWatch.expectNoGain(std::abs(clampedWatch.initialTotal));
    EXPECT_LT(deepest, 0.05);
  }
}

TEST(StepEnergyClamp, LeavesAFallingBodyAloneAndTheThesisScheduleDoesNotUseIt) {
  // A free fall keeps E = KE - m g.x exactly under the Newmark step, so nothing is clamped
  // before the first contact; the thesis schedule has no clamp (no diagnostic). The default is
  // the short schedule.
  const Registry registry = builtins();
  Simulation<2> shortRun(loadScene(kScenes + "random_drop_2d_261.json", {{"solvers.contact.schedule", "short"}}),
                         registry);
  const auto& first = shortRun.step();
  ASSERT_TRUE(first.count("step_energy_clamped_islands"));
  EXPECT_EQ(first.at("step_energy_clamped_islands"), 0);
  Simulation<2> thesisRun(loadScene(kScenes + "random_drop_2d_261.json", {{"solvers.contact.schedule", "thesis"}}),
                          registry);
  EXPECT_FALSE(thesisRun.step().count("step_energy_clamped_islands"));
  Simulation<2> defaultRun(loadScene(kScenes + "random_drop_2d_261.json"), registry);
  EXPECT_EQ(defaultRun.step().at("step_energy_clamped_islands"), 0);
  // Each schedule's values and their selection by name: test_contact_schedule.
}

TEST(JointPushOut, AJamThatTheRoundsLeaveDeepIsPushedApartAtOnce) {
  // random_drop_2d_255, step 21, on the thesis's schedule: 13 bodies between two walls, masses
  // from 0.3 to 48 kg; the rounds leave a pair 62.7 % of its thinner body deep. Its first 21
  // steps with and without the joint solve are the same up to that step's push-out.
  const Registry registry = builtins();
  auto deepestAtStep21 = [&](const std::string& joint) {
    Simulation<2> sim(loadScene(kScenes + "random_drop_2d_255.json",
                                {{"solvers.contact.schedule", "thesis"}, {"solvers.contact.push_out_joint", joint}}),
                      registry);
    std::map<std::string, double> diag;
    for (int step = 0; step < 21; ++step) diag = sim.step();
    return std::make_pair(diag.at("max_penetration_ratio"), diag.at("push_out_joint_passes"));
  };
  const auto [without, noPasses] = deepestAtStep21("false");
  const auto [with, passes] = deepestAtStep21("true");
  EXPECT_GT(without, 0.5);  // measured 0.627
  EXPECT_EQ(noPasses, 0);
  EXPECT_LT(with, 0.01);  // measured 2e-5
  EXPECT_GT(passes, 0);
}

TEST(JointPushOut, ABodyWithinReachOfAJamGivesWay) {
  // random_drop_2d_385, the first 35 steps. With the code of 64f07ff, whose jam took in only
  // the bodies overlapping it, steps 10, 11 and 35 ended 23-37 % deep; at step 35 a needle 2.5 cm into a light disk in
  // the corner of the wall and the ground, a second disk 2.9 cm off the needle's other side
  // along the same normal. That disk did not overlap, so it stayed fixed, no translation fitted,
  // and every scaled step of the linearised solve (a 13 rad turn) made the jam deeper. Now the
  // jam takes in the bodies within its deepest overlap of touching it, and grows between passes.
  const Registry registry = builtins();
  Simulation<2> sim(loadScene(kScenes + "random_drop_2d_385.json"), registry);
  double deepest = 0, passes = 0;
  for (int step = 0; step < 35; ++step) {
    const auto diag = sim.step();
    deepest = std::max(deepest, diag.at("max_penetration_ratio"));
    passes += diag.at("push_out_joint_passes");
  }
  EXPECT_LT(deepest, 0.05);  // measured 1.8 % (step 26)
  EXPECT_GT(passes, 0);      // the jam solve did run
}

TEST(JointPushOut, ATurnCostsWhatMovingItsFarthestPointWould) {
  // random_drop_2d_1421, the first 27 steps. At step 27 a disk (0.83 kg) pressed a small box
  // (0.57 kg, 13 x 7 cm) into the corner of the wall and the ground, 1.5 cm deep. Weighted by
  // its inertia alone the box turned cheaply, so the jam solve asked it to turn its corner by
  // 7-54 cm; scaled down, two passes gained little, the third made the jam deeper at every
  // halving and was undone, and the step ended 22 % deep (with the code of 50f5733). A turn now costs at least what moving the body's farthest
  // point as far would (turnMetricInverse in systems/interpenetration.cpp).
  const Registry registry = builtins();
  Simulation<2> sim(loadScene(kScenes + "random_drop_2d_1421.json"), registry);
  double deepest = 0;
  for (int step = 0; step < 27; ++step) deepest = std::max(deepest, sim.step().at("max_penetration_ratio"));
  EXPECT_LT(deepest, 0.05);  // measured 1.3 % (step 27)
}

TEST(JointPushOut, AJamClampedFromOutsideItsRingsIsSolvedAgainWithMoreRings) {
  // random_drop_2d_1227 on the short schedule, the first 120 steps (dt 1/120; 19 bodies of
  // 0.06-41 kg between two walls). Where this drop was found (before the contact stages carried
  // their manifolds, step 74), a 5.8 kg box lying on the ground was sunk 1.4 cm into it under a
  // polygon, which lay under a 28 kg disk, which a dynamic body outside the jam's two rings held
  // down: no move of the jam lifted the box, the joint solve's least-norm answer asked for moves
  // of up to 2.2 m, the bound on a pass's move scaled that to millimetres, and the step ended
  // 5.33 % deep (no regrowth: push_out_joint_regrow_overlap 1). Solved again with four rings that
  // body was in the jam and gave way. The drop now meets such a jam at step 113 (5.31 % without
  // regrowth, 2.8 % with it).
  const Registry registry = builtins();
  auto run = [&](const std::string& regrowFrom) {
    Simulation<2> sim(loadScene(kScenes + "random_drop_2d_1227.json",
                                {{"solvers.contact.schedule", "short"},
                                 {"solvers.contact.push_out_joint_regrow_overlap", regrowFrom}}),
                      registry);
    double deepest = 0, regrowths = 0;
    for (int step = 0; step < 120; ++step) {
      const auto diag = sim.step();
      deepest = std::max(deepest, diag.at("max_penetration_ratio"));
      regrowths += diag.at("push_out_joint_regrowths");
    }
    return std::make_pair(deepest, regrowths);
  };
  const auto [without, none] = run("1");
  const auto [with, regrowths] = run("0.03");  // the short schedule's
  EXPECT_GT(without, 0.05);  // measured 5.31 % (step 113)
  EXPECT_EQ(none, 0);
  EXPECT_LT(with, 0.03);  // measured 2.8 %
  EXPECT_GT(regrowths, 0);
}

TEST(PushOutNewOverlaps, APushIntoAnUntouchedNeighbourIsUndoneInTheSameStep) {
  // No gravity, no motion. Sphere C is sunk 5 cm into the static box A; box D sits 1.08 cm above
  // C's shoulder, inside C's bounding box (so the pair is in the broad phase) but not touching,
  // so Step II never processes the pair (C, D). Push-out lifts C out of A by 5 cm, which drives
  // it 3.48 cm into D. The thesis's push-out keeps to the processed pairs and leaves that; with
  // pushOutNewOverlaps (the default) D is pushed up in the same step, in either entity order.
  const Registry registry = builtins();
  auto run = [&](bool newOverlaps, bool reversed) {
    const std::string a = R"({"name": "A", "shape": {"type": "box", "half_extents": [0.5, 0.5, 0.5]},
      "rigid_body": {"static": true}, "collider": {"restitution": 0, "friction": 0.5}})";
    const std::string c = R"({"name": "C", "shape": {"type": "sphere", "radius": 0.5},
      "rigid_body": {"mass": 1, "position": [0, 0.95, 0]}, "collider": {"restitution": 0, "friction": 0.5}})";
    const std::string d = R"({"name": "D", "shape": {"type": "box", "half_extents": [0.5, 0.5, 0.5]},
      "rigid_body": {"mass": 1, "position": [0.7, 1.92, 0]}, "collider": {"restitution": 0, "friction": 0.5}})";
    const std::string text = R"({"dimension": 3, "time": {"dt": 0.03333333333333333, "end": 0.03333333333333333},
      "gravity": [0, 0, 0], "entities": [)" + (reversed ? d + "," + c + "," + a : a + "," + c + "," + d) + "]}";
    const SceneSpec scene = parseScene(text, "three_bodies.json",
                                       {{"solvers.contact.push_out_new_overlaps", newOverlaps ? "true" : "false"}});
    Simulation<3> sim(scene, registry);
    const auto diag = sim.step();
    EXPECT_TRUE(sim.finished());
    struct Result {
      double depth, cY, dY, ke;
    } r{diag.at("max_penetration"), bodyNamed(sim, "C").x.y(), bodyNamed(sim, "D").x.y(), diag.at("kinetic_energy")};
    return r;
  };
  for (bool reversed : {false, true}) {
    const auto off = run(false, reversed), on = run(true, reversed);
    // Without: C out of A, D untouched and 0.5 - |(0.2, 0.42)| = 3.48 cm deep in C.
    EXPECT_NEAR(off.cY, 1.0, 1e-4);
    EXPECT_EQ(off.dY, 1.92);
    EXPECT_NEAR(off.depth, 0.5 - std::hypot(0.2, 0.42), 1e-4);
    // With: nothing deeper than push-out's tolerance (1e-5 m) anywhere, D lifted, C still out
    // of A, and no velocity made (push-out only moves positions, App. B.1).
    EXPECT_LT(on.depth, 1e-5) << "reversed " << reversed;
    EXPECT_GT(on.dY, 1.92 + 0.02);
    EXPECT_GT(on.cY, 1.0 - 1e-4);
    EXPECT_EQ(on.ke, 0.0);
  }
}

TEST(CollisionSkip, APairThatCannotApproachIsProcessedWithoutImpulseAndABarelyApproachingOneStillCollides) {
  // No gravity. A unit box sunk 1 mm into a static one. The collision update skips the manifold
  // when no point of the pair can approach faster than the tolerance (1e-9 m/s), yet must still
  // mark the pair processed; and a corner approaching at 2e-9 m/s, by translation or by a spin
  // that leaves the centre at rest, must still get its impulse.
  const Registry registry = builtins();
  auto run = [&](const std::string& velocity, const std::string& spin) {
    const std::string text = R"({"dimension": 3, "time": {"dt": 0.03333333333333333, "end": 0.03333333333333333},
      "gravity": [0, 0, 0], "entities": [
      {"name": "A", "shape": {"type": "box", "half_extents": [0.5, 0.5, 0.5]},
       "rigid_body": {"static": true}, "collider": {"restitution": 0, "friction": 0.5}},
      {"name": "B", "shape": {"type": "box", "half_extents": [0.5, 0.5, 0.5]},
       "rigid_body": {"mass": 1, "position": [0, 0.999, 0], "velocity": )" + velocity +
                             R"(, "angular_velocity": )" + spin + R"(},
       "collider": {"restitution": 0, "friction": 0.5}}]})";
    Simulation<3> sim(parseScene(text, "two_boxes.json", {}), registry);
    return sim.step();
  };
  const auto still = run("[0, 0, 0]", "[0, 0, 0]");
  EXPECT_EQ(still.at("collision_pairs_processed"), 1);
  EXPECT_EQ(still.at("collision_impulses"), 0);
  EXPECT_EQ(still.at("contact_levels"), 2);  // B above A: the processed pair made the graph
  // Within the tolerance: 4e-10 m/s down at the centre, nothing applied.
  EXPECT_EQ(run("[0, -4e-10, 0]", "[0, 0, 0]").at("collision_impulses"), 0);
  // Beyond it: 2e-9 m/s down, by translation, and at the corners x = +0.5 by a spin about z
  // (w_z = -4e-9 rad/s: v_y = w_z x = -2e-9 m/s there).
  EXPECT_GT(run("[0, -2e-9, 0]", "[0, 0, 0]").at("collision_impulses"), 0);
  EXPECT_GT(run("[0, 0, 0]", "[0, 0, -4e-9]").at("collision_impulses"), 0);
}

TEST(PushOutRounds, APushPastTheBroadPhaseBoxIsUndoneInTheSameStep) {
  // On the thesis schedule (the short one's joint push-out from 2 % would take the 3 % overlap
  // the single round leaves). As above, but D sits 2 cm above C's bounding box (a 1 m cube 1.97 m up), so the pair
  // (C, D) is not in the broad phase when push-out starts. Lifting C 5 cm out of A drives it 3 cm
  // into D; only the broad phase grown after that push finds the pair. One round leaves the
  // overlap (the figure is reported but not pushed apart); a second round, on the bodies of the
  // pair it found, separates them in the same step.
  const Registry registry = builtins();
  auto run = [&](int rounds) {
    const std::string text = R"({"dimension": 3, "time": {"dt": 0.03333333333333333, "end": 0.03333333333333333},
      "gravity": [0, 0, 0], "entities": [
      {"name": "A", "shape": {"type": "box", "half_extents": [0.5, 0.5, 0.5]},
       "rigid_body": {"static": true}, "collider": {"restitution": 0, "friction": 0.5}},
      {"name": "C", "shape": {"type": "sphere", "radius": 0.5},
       "rigid_body": {"mass": 1, "position": [0, 0.95, 0]}, "collider": {"restitution": 0, "friction": 0.5}},
      {"name": "D", "shape": {"type": "box", "half_extents": [0.5, 0.5, 0.5]},
       "rigid_body": {"mass": 1, "position": [0, 1.97, 0]}, "collider": {"restitution": 0, "friction": 0.5}}]})";
    const SceneSpec scene =
        parseScene(text, "past_the_box.json",
                   {{"solvers.contact.schedule", "thesis"}, {"solvers.contact.push_out_rounds", std::to_string(rounds)}});
    Simulation<3> sim(scene, registry);
    const auto diag = sim.step();
    struct Result {
      double depth, rounds, left, cY, dY, ke;
    } r{diag.at("max_penetration"),         diag.at("push_out_rounds"), diag.at("push_out_overlaps_found_after"),
        bodyNamed(sim, "C").x.y(),             bodyNamed(sim, "D").x.y(),     diag.at("kinetic_energy")};
    return r;
  };
  const auto one = run(1), four = run(4);
  // One round: C out of A (top at 1.5 m), D untouched, 1.5 - 1.47 = 3 cm deep in it.
  EXPECT_NEAR(one.cY, 1.0, 1e-4);
  EXPECT_EQ(one.dY, 1.97);
  EXPECT_NEAR(one.depth, 0.03, 1e-4);
  EXPECT_EQ(one.left, 1.0);
  // Up to four (the default): a second round separates them; nothing deeper than push-out's
  // tolerance (1e-5 m) is left, C is still out of A and no velocity was made.
  EXPECT_EQ(four.rounds, 2.0);
  EXPECT_EQ(four.left, 0.0);
  EXPECT_LT(four.depth, 1e-5);
  EXPECT_GT(four.dY, 1.97 + 0.02);
  EXPECT_GT(four.cY, 1.0 - 1e-4);
  EXPECT_EQ(four.ke, 0.0);
}

TEST(PushOutNewOverlaps, SliverShardsNoLongerSinkThroughEachOther) {
  // The frame-rate sliver scene: with the thesis's push-out (processed pairs only) a shard was
  // driven deep into another that Step II had not seen touching, which the overlap metric
  // (every broad-phase pair) shows; with the new overlaps pushed apart too, it is not.
  // A single run of the chaotic pile moves by factors under any change of rounding (44 % and
  // 1.16 % when this test was written, 0.32-4.7 % for the second since), so this compares the
  // medians of five runs with gravity changed by up to 1 % (the git history of docs/benchmarks.md ("Overlaps no
  // stage saw"), "Six push-out passes" and "Shock propagation's friction"), on the thesis's
  // schedule, where those figures were measured.
  const Registry registry = builtins();
  auto median = [&](bool newOverlaps) {
    std::vector<double> runs;
    for (const char* g : {"[0, -9.81, 0]", "[0, -9.71, 0]", "[0, -9.76, 0]", "[0, -9.86, 0]", "[0, -9.91, 0]"})
      runs.push_back(deepestOverlapWithoutEnergyGain(
          loadScene(kScenes + "sliver_shards.json",
                    {{"solvers.contact.schedule", "thesis"},
                     {"solvers.contact.push_out_new_overlaps", newOverlaps ? "true" : "false"}, {"gravity", g}}),
          registry));
    std::sort(runs.begin(), runs.end());
    return runs[2];
  };
  const double thesis = median(false), ours = median(true);
  std::printf("sliver_shards, median deepest overlap of 5 runs: %.2f %% with the thesis's push-out, %.2f %% with new "
              "overlaps pushed out too\n",
              100 * thesis, 100 * ours);
  EXPECT_GT(thesis, 0.10);
  EXPECT_LT(ours, 0.02);
}

// 24 shards 1 x 0.04 x 0.5 (mass 0.5, e = 0.5, mu = 0.6) dropped from 1 to 14.8 m with random
// orientations and spins up to 8 rad/s onto a plane, dt = 1/30, 6 s: sliver_shards' layout
// with another random stream per seed.
SceneSpec randomSliverScene(unsigned seed, bool newOverlaps, const std::string& roundOverlap = "0.02",
                            const std::string& joint = "true") {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1, 1), half(0, 1);
  std::ostringstream text;
  text.precision(17);
  text << R"({"dimension": 3, "time": {"dt": 0.03333333333333333, "end": 6.0}, "gravity": [0, -9.81, 0],
    "entities": [{"name": "ground", "shape": {"type": "plane", "normal": [0, 1, 0]}, "rigid_body": {"static": true},
                  "collider": {"restitution": 0.5, "friction": 0.5}})";
  for (int i = 0; i < 24; ++i) {
    Eigen::Vector3d axis(unit(rng), unit(rng), unit(rng));
    axis.normalize();
    const double angle = EIGEN_PI * half(rng);
    const Eigen::Quaterniond q(Eigen::AngleAxisd(angle, axis));
    text << R"(, {"name": "shard_)" << i << R"(", "shape": {"type": "box", "half_extents": [0.5, 0.02, 0.25]},
      "rigid_body": {"mass": 0.5, "position": [)"
         << 1.5 * unit(rng) << ", " << 1.0 + 0.6 * i << ", " << 1.5 * unit(rng) << R"(], "orientation": [)" << q.w()
         << ", " << q.x() << ", " << q.y() << ", " << q.z() << R"(], "angular_velocity": [)" << 8 * unit(rng) << ", "
         << 8 * unit(rng) << ", " << 8 * unit(rng) << R"(]}, "collider": {"restitution": 0.5, "friction": 0.6}})";
  }
  text << "]}";
  // The thesis's schedule: the push-out figures these drops are asserted against were measured
  // on it (the git history of docs/benchmarks.md ("Six push-out passes")).
  return parseScene(text.str(), "random_slivers.json",
                    {{"solvers.contact.schedule", "thesis"},
                     {"solvers.contact.push_out_new_overlaps", newOverlaps ? "true" : "false"},
                     {"solvers.contact.push_out_round_overlap", roundOverlap},
                     {"solvers.contact.push_out_joint", joint}});
}

// The deepest overlap over all steps of a random sliver drop, which must keep the energy rules.
double randomSliverDrop(unsigned seed, bool newOverlaps, const Registry& registry,
                        const std::string& roundOverlap = "0.02") {
  return deepestOverlapWithoutEnergyGain(randomSliverScene(seed, newOverlaps, roundOverlap), registry);
}

TEST(RandomSliverDrops, MostKeepTheirOverlapsShallow) {
  // A chaotic pile gives single runs that any rounding change moves by factors, so this test
  // asserts the distribution over 12 drops (the git history of docs/benchmarks.md ("Six push-out passes")).
  const Registry registry = builtins();
  std::vector<double> on, off;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    on.push_back(randomSliverDrop(seed, true, registry));
    off.push_back(randomSliverDrop(seed, false, registry));
  }
  std::string list;
  for (std::size_t k = 0; k < on.size(); ++k) list += " " + std::to_string(100 * on[k]) + "/" + std::to_string(100 * off[k]);
  std::printf("random sliver drops, deepest overlap %% (new overlaps on/off):%s\n", list.c_str());
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  };
  const long shallow = std::count_if(on.begin(), on.end(), [](double r) { return r < 0.03; });
  EXPECT_LT(median(on), 0.01);  // measured 0.28 %
  EXPECT_GE(shallow, 10);  // measured: all 12 under 2.2 %
  // The thesis's push-out (processed pairs only) leaves the pile's shards deep in each other.
  EXPECT_GT(median(off), 0.10);  // measured 52 %
}

TEST(PushOutRounds, APushPastTheBroadPhaseBoxIsUndoneInTheSameStepIn2D) {
  // The same in 2-D: a disk sunk 5 cm into a static square, a square 2 cm above its box.
  const Registry registry = builtins();
  auto run = [&](int rounds) {
    const std::string text = R"({"dimension": 2, "time": {"dt": 0.03333333333333333, "end": 0.03333333333333333},
      "gravity": [0, 0], "entities": [
      {"name": "A", "shape": {"type": "box", "half_extents": [0.5, 0.5]},
       "rigid_body": {"static": true}, "collider": {"restitution": 0, "friction": 0.5}},
      {"name": "C", "shape": {"type": "disk", "radius": 0.5},
       "rigid_body": {"mass": 1, "position": [0, 0.95]}, "collider": {"restitution": 0, "friction": 0.5}},
      {"name": "D", "shape": {"type": "box", "half_extents": [0.5, 0.5]},
       "rigid_body": {"mass": 1, "position": [0, 1.97]}, "collider": {"restitution": 0, "friction": 0.5}}]})";
    Simulation<2> sim(parseScene(text, "past_the_box_2d.json",
                                 {{"solvers.contact.schedule", "thesis"}, {"solvers.contact.push_out_rounds", std::to_string(rounds)}}),
                      registry);
    const auto diag = sim.step();
    return std::make_pair(diag.at("max_penetration"), bodyNamed(sim, "D").x.y());
  };
  const auto [oneDepth, oneD] = run(1);
  const auto [fourDepth, fourD] = run(4);
  EXPECT_NEAR(oneDepth, 0.03, 1e-4);
  EXPECT_EQ(oneD, 1.97);
  EXPECT_LT(fourDepth, 1e-5);
  EXPECT_GT(fourD, 1.97 + 0.02);
}

TEST(PushOutRounds, ANeedleAtAWallsFootLeavesThroughTheWallsInnerFace) {
  // No gravity, no motion. A wall box 2 m tall, 20 cm thick; a needle 1 cm thick lies at its
  // foot, 1 mm into the ground and 5 cm into the wall.
  // - Wall hovering 1 mm above the ground: its least-penetration direction is its bottom face
  //   (8 mm down, into the ground), the ground's is up. The first round, the thesis's, cannot
  //   satisfy both and leaves the needle deep; a later round takes the wall's inner face instead
  //   (escapeThroughBoxFace): 5 cm out along +z.
  // - Wall standing on the ground: its box reaches down through the plane (grounded_box.h), so
  //   its bottom face is no way out, and already the first round pushes the needle out of the
  //   inner face.
  // - Wall standing on a floor box 1 m thick instead of the plane: the wall reaches into the
  //   floor box, and again the first round suffices.
  // The joint solve after the rounds is off unless asked for: these cases are the rounds'.
  const Registry registry = builtins();
  auto run = [&](double wallBottom, int rounds, bool floorBox = false, bool joint = false) {
    const std::string ground =
        floorBox ? R"({"name": "ground", "shape": {"type": "box", "half_extents": [5, 0.5, 5]},
       "rigid_body": {"static": true, "position": [0, -0.5, 0]}, "collider": {"restitution": 0, "friction": 0.5}},)"
                 : R"({"name": "ground", "shape": {"type": "plane", "normal": [0, 1, 0]}, "rigid_body": {"static": true},
       "collider": {"restitution": 0, "friction": 0.5}},)";
    const std::string text = R"({"dimension": 3, "time": {"dt": 0.016666666666666666, "end": 0.016666666666666666},
      "gravity": [0, 0, 0], "entities": [
      )" + ground + R"(
      {"name": "wall", "shape": {"type": "box", "half_extents": [1, 1, 0.1]},
       "rigid_body": {"static": true, "position": [0, )" + std::to_string(1 + wallBottom) + R"(, -0.1]}, "collider": {"restitution": 0, "friction": 0.5}},
      {"name": "needle", "shape": {"type": "box", "half_extents": [0.005, 0.005, 0.1]},
       "rigid_body": {"mass": 1, "position": [0, 0.004, 0.05]}, "collider": {"restitution": 0, "friction": 0.5}}]})";
    Simulation<3> sim(parseScene(text, "wall_foot.json",
                                 {{"solvers.contact.push_out_rounds", std::to_string(rounds)},
                                  {"solvers.contact.push_out_joint", joint ? "true" : "false"}}),
                      registry);
    const auto diag = sim.step();
    return std::make_pair(diag.at("max_penetration_ratio"), positionOf(sim, "needle"));
  };
  const auto [hoverOne, hoverOneX] = run(0.001, 1);
  const auto [hoverFour, hoverFourX] = run(0.001, 4);
  EXPECT_GT(hoverOne, 0.5);  // measured 0.82 (0.83 on the ground before grounded_box.h)
  EXPECT_LT(hoverFour, 0.01);
  EXPECT_NEAR(hoverFourX.z(), 0.05 + 0.05, 2e-3);  // out of the wall's inner face, z = 0
  EXPECT_NEAR(hoverFourX.y(), 0.005, 2e-3);        // resting on the ground, not pushed into it
  for (bool floorBox : {false, true})
    for (int rounds : {1, 4}) {
      const auto [ratio, x] = run(0, rounds, floorBox);
      EXPECT_LT(ratio, 0.01) << rounds << " rounds, floor box " << floorBox;
      EXPECT_NEAR(x.z(), 0.05 + 0.05, 2e-3) << rounds << " rounds, floor box " << floorBox;
      EXPECT_NEAR(x.y(), 0.005, 2e-3) << rounds << " rounds, floor box " << floorBox;
    }
  // The same hovering wall over the floor box: not extended, so only the later rounds help.
  EXPECT_GT(run(0.001, 1, true).first, 0.5);
  // The joint solve after the rounds (joint_push_out.h, on by default; off above) also takes the
  // needle out when one round leaves it deep.
  EXPECT_LT(run(0.001, 1, false, true).first, 0.01);
}

TEST(PushOutRounds, TheFirstStepThatNeedsFurtherRoundsEndsShallowerWithThem) {
  // Random sliver drops with and without rounds for residual overlaps (push_out_round_overlap
  // 0.02, the default, against 1e9). Until a step needs a second round the two runs are the
  // same bitwise; at that step the rounds, kept or undone, must leave the deepest overlap no
  // deeper than one round does, and over the drops they must cut it. (Whole runs cannot be
  // compared: from that step on the piles differ, and any difference moves a chaotic pile's
  // later overlaps by factors either way -- the git history of docs/benchmarks.md ("Push-out in rounds").)
  // Seeds: the first ten of 1-240 whose runs without rounds exceed 5 % (measured 2026-11-27,
  // chosen again 2026-11-28 after shock propagation's friction changed the piles, and
  // 2026-11-29 after the contact stages began to carry their manifolds).
  const Registry registry = builtins();
  int compared = 0, shallower = 0;
  double sumOn = 0, sumOff = 0;
  for (unsigned seed : {6u, 13u, 16u, 19u, 30u, 60u, 66u, 78u, 83u, 88u}) {
    // The joint solve after the rounds (joint_push_out.h) off in both: it would also take the
    // deep pairs the run without rounds leaves.
    Simulation<3> on(randomSliverScene(seed, true, "0.02", "false"), registry),
        off(randomSliverScene(seed, true, "1e9", "false"), registry);
    while (!on.finished()) {
      const auto& a = on.step();
      const auto& b = off.step();
      // The first step where the runs part: the one where a residual overlap took a round.
      const bool same = a.at("total_energy") == b.at("total_energy") &&
                        a.at("max_penetration_ratio") == b.at("max_penetration_ratio") &&
                        a.at("push_out_rounds") == b.at("push_out_rounds") &&
                        a.at("push_out_rounds_undone") == b.at("push_out_rounds_undone");
      if (same) continue;
      EXPECT_GT(a.at("push_out_rounds") + a.at("push_out_rounds_undone"), 1) << "seed " << seed;
      EXPECT_LE(a.at("max_penetration_ratio"), b.at("max_penetration_ratio") + 1e-12) << "seed " << seed;
      ++compared;
      shallower += a.at("max_penetration_ratio") < b.at("max_penetration_ratio") ? 1 : 0;
      sumOn += a.at("max_penetration_ratio");
      sumOff += b.at("max_penetration_ratio");
      std::printf("seed %u, step %ld: deepest overlap %.2f %% with rounds, %.2f %% without\n", seed, on.stepsDone(),
                  100 * a.at("max_penetration_ratio"), 100 * b.at("max_penetration_ratio"));
      break;
    }
  }
  // Measured: 10 compared, 8 shallower, the sum of the ten 0.06 of that without rounds (jams of
  // 28-198 % cut to 0.1-6.6 %; two steps the rounds could not improve, 10.0 % and 2.2 %).
  EXPECT_GE(compared, 8);
  EXPECT_GE(shallower, compared / 2);
  EXPECT_LT(sumOn, 0.85 * sumOff);
}

TEST(BroadPhaseGrowth, ABallThatBouncesIntoABallItWasNeverPairedWithDoesNotSinkIntoIt) {
  // No gravity. Ball A (r = 0.5) falls at 6 m/s, 0.1 above the ground; ball B hangs 0.15 above
  // it. The broad-phase box of A covers its motion down (y -0.1 .. 1.1) and misses B (from
  // 1.25), so the pair (A, B) is not in the list Step II works on. A bounces (e = 1) and its
  // step up, 0.2 at dt = 1/30, would put it 0.05 deep into B, unseen by contact, push-out and
  // the overlap metric. The pairs are found again where the impulses sent the bodies
  // (ContactWorkspace::growPairs): contact then stops A at B.
  const Registry registry = builtins();
  const std::string text = R"({"dimension": 3, "time": {"dt": 0.03333333333333333, "end": 0.03333333333333333},
    "gravity": [0, 0, 0], "entities": [
      {"name": "ground", "shape": {"type": "plane", "normal": [0, 1, 0]}, "rigid_body": {"static": true},
       "collider": {"restitution": 1, "friction": 0}},
      {"name": "A", "shape": {"type": "sphere", "radius": 0.5},
       "rigid_body": {"mass": 1, "position": [0, 0.6, 0], "velocity": [0, -6, 0]}, "collider": {"restitution": 1, "friction": 0}},
      {"name": "B", "shape": {"type": "sphere", "radius": 0.5},
       "rigid_body": {"mass": 1, "position": [0, 1.75, 0]}, "collider": {"restitution": 1, "friction": 0}}]})";
  Simulation<3> sim(parseScene(text, "bounce_into.json"), registry);
  const double energy0 = 0.5 * 36;
  const auto diag = sim.step();
  ASSERT_TRUE(sim.finished());
  EXPECT_EQ(diag.at("contact_pairs_broad_phase"), 3);  // ground-A, ground-B, and A-B found again
  EXPECT_EQ(diag.at("broad_phase_pairs_added_after_collisions"), 1);
  const RigidBody<3>&a = bodyNamed(sim, "A"), &b = bodyNamed(sim, "B");
  // A bounced: moving up, and not into B (distance of the centres at least the sum of radii,
  // up to push-out's 1e-5 m tolerance).
  EXPECT_GT(a.v.y(), 0);
  EXPECT_GE((b.x - a.x).norm(), 1.0 - 1e-5);
  EXPECT_LT(diag.at("max_penetration"), 1e-5);
  // The ground's bounce gave the pair 12 kg m/s of upward momentum; A and B share it, none lost
  // sideways, and no energy was made.
  EXPECT_NEAR(a.v.y() + b.v.y(), 6.0, 1e-9);
  EXPECT_NEAR(a.v.x() + b.v.x(), 0.0, 1e-12);
  EXPECT_LE(diag.at("kinetic_energy"), energy0 * (1 + 1e-12));
}

TEST(ContactDeterminism, EveryShapePairGivesTheSameStateOnOneAndTwoThreads) {
  // The mixed pile's narrow phase (EPA starts, capsule rims, hull edges) on both threads.
  expectSameStateOnOneAndTwoThreads("mixed_pile.json", "1.5");
}

TEST(EnergyClamp, SliverShardsGainEnergyOnlyWithoutTheClamp) {
  // The thesis's collision test at the candidate poses (swept collisions off): there the split
  // state's lever arms of slivers sunk deep into each other make impulses that gain energy.
  // Swept collisions test the slivers where they first touch instead, and in this scene no
  // impulse gains energy even without the clamp (the git history of docs/benchmarks.md ("Swept collisions")).
  const Registry registry = builtins();
  auto run = [&](bool clamp, const char* gravity) {
    const SceneSpec scene = loadScene(kScenes + "sliver_shards.json",
                                      {{"solvers.contact.energy_clamp", clamp ? "true" : "false"},
                                       {"solvers.contact.swept_collisions", "false"},
                                       {"gravity", gravity}});
    Simulation<3> sim(scene, registry);
    EnergyWatch watch;
    while (!sim.finished()) watch.observe(sim.step());
    return watch;
  };
  // Which impulses gain is chaotic (the scene as written showed it until shock propagation's
  // friction changed, 2026-11-28): the scene and four variants with gravity changed by up to 1 %.
  double gainOff = 0;
  for (const char* g : {"[0, -9.81, 0]", "[0, -9.71, 0]", "[0, -9.76, 0]", "[0, -9.86, 0]", "[0, -9.91, 0]"}) {
    const EnergyWatch on = run(true, g), off = run(false, g);
    on.expectNoGain(std::abs(on.initialTotal));
    gainOff = std::max({gainOff, off.worstCollisionGain, off.worstContactGain});
  }
  std::printf("sliver_shards without the clamp: worst impulse gain %.2e J over 5 runs\n", gainOff);
  EXPECT_GT(gainOff, 1e-6) << "without the clamp frame-rate slivers should show energy gain in some impulse";
}

TEST(SweptCollisions, PlatesThrownAtAThinShelfStopOnItAtFrameRate) {
  // A 4 cm plate thrown down at a static 4 cm shelf, dt = 1/30: from 3, 6 and 20 m/s it moves
  // 2.5 to 17 thicknesses per step. Tested only at the candidate poses (the thesis's Step II)
  // it is past the shelf there from 6 m/s on and falls through to the ground; tested where it
  // first touches along its motion (swept_contact.h) it lands on the shelf every time.
  // On both schedules: the short one lands the plate by closing the gap its
  // collision stage stops it above (ContactSettings::closeGaps; without it the plate rests
  // 2-4.5 mm above the shelf), the thesis's by its ramped sweeps.
  const Registry registry = builtins();
  std::string schedule;
  auto finalHeight = [&](double speed, bool swept) {
    std::ostringstream text;
    text << R"({"dimension": 3, "time": {"dt": 0.03333333333333333, "end": 1.0}, "gravity": [0, -9.81, 0],
      "entities": [
        {"name": "ground", "shape": {"type": "plane", "normal": [0, 1, 0]}, "rigid_body": {"static": true},
         "collider": {"restitution": 0, "friction": 0.5}},
        {"name": "shelf", "shape": {"type": "box", "half_extents": [0.5, 0.02, 0.25]},
         "rigid_body": {"static": true, "position": [0, 2, 0]}, "collider": {"restitution": 0, "friction": 0.5}},
        {"name": "plate", "shape": {"type": "box", "half_extents": [0.5, 0.02, 0.25]},
         "rigid_body": {"mass": 0.5, "position": [0.1, 3, 0.05], "velocity": [0, )"
         << -speed << R"(, 0]}, "collider": {"restitution": 0, "friction": 0.5}}]})";
    const SceneSpec scene = parseScene(text.str(), "plates.json",
                                       {{"solvers.contact.schedule", schedule},
                                        {"solvers.contact.swept_collisions", swept ? "true" : "false"}});
    Simulation<3> sim(scene, registry);
    EnergyWatch watch;
    double worst = 0, sweptPairs = 0;
    while (!sim.finished()) {
      const auto& diag = sim.step();
      watch.observe(diag);
      worst = std::max(worst, diag.at("max_penetration_ratio"));
      sweptPairs += diag.at("collision_pairs_swept");
    }
    EXPECT_LE(worst, 0.01);
    watch.expectNoGain(std::abs(watch.initialTotal));
    EXPECT_LT(bodyNamed(sim, "plate").v.norm(), 1e-3);
    // The metric counts the fast pairs met where they first touch: the landing (stopped at its
    // start-of-step pose, the plate falls the rest of the gap and lands again, as in the thesis's
    // Step II), and nothing once it rests (it would keep counting if a resting pair were taken
    // for a fast one).
    if (swept) {
      EXPECT_GE(sweptPairs, 1) << "thrown at " << speed << " m/s";
      EXPECT_LE(sweptPairs, 5) << "thrown at " << speed << " m/s";
    } else {
      EXPECT_EQ(sweptPairs, 0);
    }
    return positionOf(sim, "plate").y();
  };
  for (const char* name : {"thesis", "short"}) {
    schedule = name;
    SCOPED_TRACE(schedule);
    for (double speed : {3.0, 6.0, 20.0}) {
      EXPECT_NEAR(finalHeight(speed, true), 2.04, 1e-3) << "thrown at " << speed << " m/s: resting on the shelf";
      if (speed > 5) {
        EXPECT_NEAR(finalHeight(speed, false), 0.02, 1e-3) << "the candidate test lets it through";
      }
    }
  }
}

TEST(SweptCollisions, InTwoDimensionsADiskThrownAtAThinBarStopsOnIt) {
  // The same in 2-D: a disk (r 0.1) thrown down at 15 m/s, 2.5 diameters per step at dt = 1/30,
  // at a static bar 2 cm thick. With the candidate test alone it ends on the ground below.
  const Registry registry = builtins();
  std::string schedule;
  auto finalHeight = [&](bool swept) {
    const std::string text = R"({"dimension": 2, "time": {"dt": 0.03333333333333333, "end": 1.0}, "gravity": [0, -9.81],
      "entities": [
        {"name": "ground", "shape": {"type": "plane", "normal": [0, 1]}, "rigid_body": {"static": true},
         "collider": {"restitution": 0, "friction": 0.5}},
        {"name": "bar", "shape": {"type": "box", "half_extents": [1.0, 0.01]},
         "rigid_body": {"static": true, "position": [0, 2]}, "collider": {"restitution": 0, "friction": 0.5}},
        {"name": "disk", "shape": {"type": "disk", "radius": 0.1},
         "rigid_body": {"mass": 1, "position": [0.05, 3], "velocity": [0, -15]},
         "collider": {"restitution": 0, "friction": 0.5}}]})";
    // Both schedules, as above (without closing gaps the short one left the disk 3 mm above the bar).
    Simulation<2> sim(parseScene(text, "disk.json",
                                 {{"solvers.contact.schedule", schedule},
                                  {"solvers.contact.swept_collisions", swept ? "true" : "false"}}),
                      registry);
    EnergyWatch watch;
    while (!sim.finished()) watch.observe(sim.step());
    watch.expectNoGain(std::abs(watch.initialTotal));
    return positionOf(sim, "disk").y();
  };
  for (const char* name : {"thesis", "short"}) {
    schedule = name;
    SCOPED_TRACE(schedule);
    EXPECT_NEAR(finalHeight(true), 2.11, 1e-3) << "resting on the bar (its top at 2.01)";
    EXPECT_NEAR(finalHeight(false), 0.1, 1e-3) << "the candidate test lets it through to the ground";
  }
}

TEST(MeshGround, SphereAndBoxComeToRestOnAnObjMesh) {
  // A ground read from a Wavefront OBJ file (two triangles, path relative to the scene):
  // a sphere and a box dropped on it rest at their half heights.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "monolith_mesh_ground";
  std::filesystem::create_directories(dir);
  {
    std::ofstream obj(dir / "ground.obj");
    obj << "v -5 0 -5\nv 5 0 -5\nv 5 0 5\nv -5 0 5\nf 1 3 2\nf 1 4 3\n";
    std::ofstream scene(dir / "scene.json");
    scene << R"({"dimension": 3, "time": {"dt": 0.016666666666666666, "end": 1.5}, "gravity": [0, -9.81, 0],
      "entities": [
        {"name": "ground", "shape": {"type": "mesh", "file": "ground.obj"}, "rigid_body": {"static": true},
         "collider": {"restitution": 0, "friction": 0.5}},
        {"name": "ball", "shape": {"type": "sphere", "radius": 0.5}, "rigid_body": {"mass": 1, "position": [-2, 1, 0]},
         "collider": {"restitution": 0, "friction": 0.5}},
        {"name": "box", "shape": {"type": "box", "half_extents": [0.3, 0.2, 0.3]}, "rigid_body": {"mass": 1, "position": [2, 0.8, 0]},
         "collider": {"restitution": 0, "friction": 0.5}}]})";
  }
  const Registry registry = builtins();
  Simulation<3> sim(loadScene((dir / "scene.json").string()), registry);
  EnergyWatch watch;
  while (!sim.finished()) watch.observe(sim.step());
  EXPECT_NEAR(positionOf(sim, "ball").y(), 0.5, 2e-3);
  EXPECT_NEAR(positionOf(sim, "box").y(), 0.2, 2e-3);
  EXPECT_LT(bodyNamed(sim, "ball").v.norm(), 1e-3);
  EXPECT_LT(bodyNamed(sim, "box").v.norm(), 1e-3);
  watch.expectNoGain(std::abs(watch.initialTotal));
}

TEST(MeshGround, ADynamicMeshCubeRestsAsTheBoxItBounds) {
  // A closed triangle mesh as a dynamic body (meshes are static or dynamic): a unit cube
  // read from an OBJ file dropped 5 cm onto the ground, a small box dropped onto it off its
  // centre, beside a box-shaped unit cube and small box dropped the same way 6 m away. The mesh
  // cube meets the plane with its vertices, as the box does, and the small box meets the mesh's
  // triangles (FCL per triangle plus the feature points) where the other meets a box
  // (box_box.cpp): the two stacks must come to rest at the same heights and stay put.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "monolith_dynamic_mesh";
  std::filesystem::create_directories(dir);
  test::writeUnitCubeObj(dir / "cube.obj");
  {
    std::ofstream scene(dir / "scene.json");
    scene << R"({"dimension": 3, "time": {"dt": 0.016666666666666666, "end": 4}, "gravity": [0, -9.81, 0],
      "entities": [
        {"name": "ground", "shape": {"type": "plane", "normal": [0, 1, 0]}, "rigid_body": {"static": true},
         "collider": {"restitution": 0, "friction": 0.5}},
        {"name": "mesh_cube", "shape": {"type": "mesh", "file": "cube.obj"},
         "rigid_body": {"mass": 1, "inertia": [0.16666666666666666, 0.16666666666666666, 0.16666666666666666],
                        "position": [-3, 0.55, 0]}, "collider": {"restitution": 0, "friction": 0.5}},
        {"name": "on_mesh", "shape": {"type": "box", "half_extents": [0.3, 0.2, 0.3]},
         "rigid_body": {"mass": 1, "position": [-2.9, 1.3, 0.05]}, "collider": {"restitution": 0, "friction": 0.5}},
        {"name": "box_cube", "shape": {"type": "box", "half_extents": [0.5, 0.5, 0.5]},
         "rigid_body": {"mass": 1, "position": [3, 0.55, 0]}, "collider": {"restitution": 0, "friction": 0.5}},
        {"name": "on_box", "shape": {"type": "box", "half_extents": [0.3, 0.2, 0.3]},
         "rigid_body": {"mass": 1, "position": [3.1, 1.3, 0.05]}, "collider": {"restitution": 0, "friction": 0.5}}]})";
  }
  const Registry registry = builtins();
  // On both schedules (without closing gaps the short one left the box resting 0.7 mm above the cube, stopped in the air by its one fully inelastic contact pass).
  for (const char* schedule : {"thesis", "short"}) {
    SCOPED_TRACE(schedule);
    Simulation<3> sim(loadScene((dir / "scene.json").string(), {{"solvers.contact.schedule", schedule}}), registry);
    EnergyWatch watch;
    double apart = 0;  // the two stacks' largest difference in any body position, any step
    const Eigen::Vector3d shift(6, 0, 0);
    while (!sim.finished()) {
      watch.observe(sim.step());
      apart = std::max({apart, (positionOf(sim, "box_cube") - positionOf(sim, "mesh_cube") - shift).norm(),
                        (positionOf(sim, "on_box") - positionOf(sim, "on_mesh") - shift).norm()});
    }
    const Eigen::Vector3d slid = positionOf(sim, "on_mesh") - Eigen::Vector3d(-2.9, 1.2, 0.05);
    std::printf("dynamic mesh cube rests at %.6f, the box on it at %.6f, %.2e from where it landed; stacks apart by %.2e "
                "at most\n",
                positionOf(sim, "mesh_cube").y(), positionOf(sim, "on_mesh").y(), slid.norm(), apart);
    EXPECT_NEAR(positionOf(sim, "mesh_cube").y(), 0.5, 1e-3);
    EXPECT_LT(slid.norm(), 1e-3);
    EXPECT_LT(apart, 1e-4);
    for (const char* name : {"mesh_cube", "on_mesh", "box_cube", "on_box"}) EXPECT_LT(bodyNamed(sim, name).v.norm(), 1e-3) << name;
    watch.expectNoGain(std::abs(watch.initialTotal));
  }
}

// A box placed off the centre of a unit cube on the ground, both at rest, in 3-D or 2-D: the
// largest distance either moved in `seconds`, and their final speed.
std::pair<double, double> offCentreStack(int dimension, double seconds, bool shortSchedule = false) {
  const bool three = dimension == 3;
  std::ostringstream text;
  text << R"({"dimension": )" << dimension << R"(, "time": {"dt": 0.016666666666666666, "end": )" << seconds
       << R"(}, "gravity": )" << (three ? "[0, -9.81, 0]" : "[0, -9.81]") << R"(,
    "entities": [
      {"name": "ground", "shape": {"type": "plane", "normal": )" << (three ? "[0, 1, 0]" : "[0, 1]")
       << R"(}, "rigid_body": {"static": true}, "collider": {"restitution": 0, "friction": 0.5}},
      {"name": "cube", "shape": {"type": "box", "half_extents": )" << (three ? "[0.5, 0.5, 0.5]" : "[0.5, 0.5]")
       << R"(}, "rigid_body": {"mass": 1, "position": )" << (three ? "[0, 0.5, 0]" : "[0, 0.5]")
       << R"(}, "collider": {"restitution": 0, "friction": 0.5}},
      {"name": "top", "shape": {"type": "box", "half_extents": )" << (three ? "[0.3, 0.2, 0.3]" : "[0.3, 0.2]")
       << R"(}, "rigid_body": {"mass": 1, "position": )" << (three ? "[0.1, 1.2, 0.05]" : "[0.1, 1.2]")
       << R"(}, "collider": {"restitution": 0, "friction": 0.5}}]})";
  const Registry registry = builtins();
  double moved = 0, speed = 0;
  auto run = [&](auto& sim) {
    const auto cube0 = positionOf(sim, "cube"), top0 = positionOf(sim, "top");
    EnergyWatch watch;
    while (!sim.finished()) {
      watch.observe(sim.step());
      moved = std::max({moved, (positionOf(sim, "cube") - cube0).norm(), (positionOf(sim, "top") - top0).norm()});
    }
    watch.expectNoGain(std::abs(watch.initialTotal));
    speed = std::max(bodyNamed(sim, "cube").v.norm(), bodyNamed(sim, "top").v.norm());
  };
  std::vector<Override> overrides;
  if (shortSchedule)
    overrides = {{"solvers.contact.contact_iterations", "1"},
                 {"solvers.contact.contact_level_iterations", "1"},
                 {"solvers.contact.shock_level_iterations", "1"},
                 {"solvers.contact.exact_manifold_finish", "true"}};
  if (three) {
    Simulation<3> sim(parseScene(text.str(), "off_centre_stack.json", overrides), registry);
    run(sim);
  } else {
    Simulation<2> sim(parseScene(text.str(), "off_centre_stack.json", overrides), registry);
    run(sim);
  }
  return {moved, speed};
}

TEST(ShockPropagation, AnOffCentreBoxOnABoxStaysPut) {
  // A 0.6 x 0.4 x 0.6 box resting 10 cm and 5 cm off the centre of a unit cube, both of 1 kg, at
  // dt = 1/60. The contact sweeps leave both a slip of millimetres per second in the direction
  // of the offset, with no approach left for shock propagation's friction to push against; it
  // used to stay, and the stack walked (2.3 cm in 6 s, 17 cm in 30 s, still faster). Shock
  // propagation's friction now leans on the normal impulse the pair carried earlier in the
  // stage (ContactWorkspace::findPairImpulse): 0.2 mm of settling, then nothing.
  // Also on the short schedule with the exact finish, whose points are prepared for the finish
  // only: the re-solve must prepare them for sweeps (a first version did not, and 2-D random
  // drops on that schedule blew up).
  for (bool shortSchedule : {false, true})
    for (int dimension : {3, 2}) {
      const auto [moved, speed] = offCentreStack(dimension, 10.0, shortSchedule);
      std::printf("off-centre stack, %d-D%s: moved %.2e m in 10 s, final speed %.2e m/s\n", dimension,
                  shortSchedule ? ", short schedule" : "", moved, speed);
      EXPECT_LT(moved, 1e-3) << dimension << "-D" << (shortSchedule ? ", short schedule" : "");
      EXPECT_LT(speed, 1e-3) << dimension << "-D" << (shortSchedule ? ", short schedule" : "");
    }
}

TEST(ShockPropagation, APlankOnAStaticAndAKinematicBlockKeepsUpWithTheLift) {
  // A plank across a static pillar (x = -1) and a kinematic lift (x = +1) rising at 0.3 m/s: its
  // right end must ride the lift, pivoting on the pillar. A body supported by a static and a
  // kinematic body at once: in shock propagation the kinematic partner keeps the pair out of
  // the joint solve, so each pair gets its own update. (Until 2026-11-24 the lift's pair was
  // skipped there; that changed the deepest overlap, 1.3e-9 -> 2.0e-10 m, but not what this
  // test measures, which the contact sweeps before it already settle.)
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "monolith_plank_lift";
  std::filesystem::create_directories(dir);
  const std::string scene = (dir / "plank_lift.json").string();
  std::ofstream(scene) << R"({
    "dimension": 3, "time": { "dt": 0.03333333333333333, "end": 1.5 }, "gravity": [0, -9.81, 0],
    "entities": [
      { "name": "plank", "shape": { "type": "box", "half_extents": [1.5, 0.1, 0.5] },
        "rigid_body": { "mass": 1, "position": [0, 0.1, 0] }, "collider": { "friction": 0.8 } },
      { "name": "pillar", "shape": { "type": "box", "half_extents": [0.5, 0.5, 0.5] },
        "rigid_body": { "static": true, "position": [-1, -0.5, 0] }, "collider": { "friction": 0.8 } },
      { "name": "lift", "shape": { "type": "box", "half_extents": [0.5, 0.5, 0.5] },
        "rigid_body": { "mass": 100, "position": [1, -0.5, 0] }, "kinematic": { "velocity": [0, 0.3, 0] },
        "collider": { "friction": 0.8 } } ] })";
  const Registry registry = builtins();
  Simulation<3> sim(loadScene(scene), registry, 1);
  double worstApproach = 0;
  while (!sim.finished()) {
    sim.step();
    const RigidBody<3>& plank = bodyNamed(sim, "plank");
    const RigidBody<3>& lift = bodyNamed(sim, "lift");
    // The plank's lowest point above the lift's far edge (its underside at x = +1.5 in the
    // plank's frame), and its velocity relative to the lift along the lift's top normal.
    const Eigen::Vector3d corner = plank.x + plank.orientation * Eigen::Vector3d(1.5, -0.1, 0);
    const Eigen::Vector3d v = plank.v + plank.omega().cross(corner - plank.x);
    worstApproach = std::max(worstApproach, lift.v.y() - v.y());
  }
  // 1 % of the lift speed: at the end of each step the plank's end moves up with the lift.
  EXPECT_LT(worstApproach, 0.01 * 0.3);
  EXPECT_GT(positionOf(sim, "plank").y(), 0.1 + 0.5 * 0.3 * 1.5 - 0.01);  // lifted at one end
}

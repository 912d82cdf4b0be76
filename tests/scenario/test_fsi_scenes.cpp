// Two-way coupled rigid bodies in the fluid (fluid_coupling; thesis Sec. 5.4-5.8, 5.11.1-2):
// the channel plate's terminal velocity converging at first order to the analytic value with the
// plate's weight carried by the coupling impulses, the solve's kinetic energy never rising, the
// falling cylinder stable at mass ratios 1e-9 and 1e9, Stokes mode, 1 vs 2 threads bitwise, and
// bad scenes refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "components/mac_grid.h"
#include "components/rigid_body.h"
#include "ecs/config.h"
#include "scenarios/scene.h"
#include "scenarios/simulation.h"
#include "support/scenes.h"

using namespace monolith;
using namespace monolith::test;

namespace {

struct PlateRun {
  double velocity = 0, force = 0, maxEnergyChange = -1e300, kinetic = 0;
  long steps = 0;
};

PlateRun runPlate(const Registry& registry, int n, std::vector<Override> overrides = {}) {
  overrides.push_back({"entities.fluid.mac_grid.cells", "[" + std::to_string(n) + "," + std::to_string(n) + "]"});
  Simulation<2> sim(loadScene(kScenes + "channel_plate.json", overrides), registry, 2);
  PlateRun r;
  while (!sim.finished()) {
    const auto& m = sim.step();
    r.velocity = m.at("fsi_plate_velocity_y");
    r.force = m.at("fsi_plate_force_y");
    r.maxEnergyChange = std::max({r.maxEnergyChange, m.at("fsi_energy_change"), m.at("fsi_half_step_energy_change")});
    r.kinetic = m.at("fluid_kinetic_energy");
    ++r.steps;
  }
  return r;
}


}  // namespace

// Sec. 5.11.1: v_s = -(M + rho w h) g w / (2 h mu) = -2.9944 m/s. docs/benchmarks_fsi.md measures
// errors 0.306, 0.153, 0.0764, ... at 12, 24, 48, ... cells (order 1.00; the thesis fits 0.93): the
// plate is too fast by about 1.2 dx / w of its speed (the tangential coupling sits half a cell
// inside the plate, widening each gap by dx / 2). Bounds: 12 cells within 11 %, 24 cells within
// 55 % of the 12-cell error (an observed order of at least 0.86).
TEST(FsiChannelPlate, TerminalVelocityConvergesAtFirstOrder) {
  const Registry registry = builtins();
  const double exact = -(150.0 + 100.0 / 3.0) * 9.8 / 3.0 / (2.0 * 100.0);
  EXPECT_NEAR(exact, -2.9944, 1e-4);
  const PlateRun coarse = runPlate(registry, 12), fine = runPlate(registry, 24);
  const double e12 = std::abs(coarse.velocity - exact), e24 = std::abs(fine.velocity - exact);
  EXPECT_LT(e12, 0.11 * std::abs(exact)) << coarse.velocity;
  EXPECT_LT(e24, 0.55 * e12) << fine.velocity;
  // Steady: the fluid's force on the plate from the coupling impulses carries its weight M g.
  EXPECT_NEAR(fine.force, 150.0 * 9.8, 0.002 * 150.0 * 9.8);
  // Sec. 5.8: no coupled solve (half or full step) adds kinetic energy; the fluid holds ~10^3 J,
  // so 1e-9 J is far below one part in 10^10 of it.
  EXPECT_LE(coarse.maxEnergyChange, 1e-9);
  EXPECT_LE(fine.maxEnergyChange, 1e-9);
  EXPECT_GT(fine.kinetic, 100.0);
}

// "obstacle_wall": "surface": the shear rows between the fluid and the plate measure against the
// plate's side (half a cell from the first fluid face) instead of the faces half a cell inside it;
// the steady speed is then the analytic one to the steady state's settling (measured 8.4e-5 of
// v_s at 12 cells, against 10.2 % with the thesis's placement), its weight still carried by the
// coupling impulses, no solve adding energy.
TEST(FsiChannelPlate, WallsAtTheSurfaceGiveTheAnalyticSpeed) {
  const Registry registry = builtins();
  const double exact = -(150.0 + 100.0 / 3.0) * 9.8 / 3.0 / (2.0 * 100.0);
  const PlateRun r = runPlate(registry, 12, {{"solvers.fluid.obstacle_wall", "surface"}});
  EXPECT_LT(std::abs(r.velocity / exact - 1), 1e-3) << r.velocity;
  EXPECT_NEAR(r.force, 150.0 * 9.8, 0.002 * 150.0 * 9.8);
  EXPECT_LE(r.maxEnergyChange, 1e-9);
}

// falling_cylinder's text without its CFL step: in Stokes flow the steady state is the fixed point
// of the step for any dt, so a few steps of 100 s reach it.
std::string cylinderWithoutCfl() {
  std::ifstream in(kScenes + "falling_cylinder.json");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string cfl = "\"cfl\": 0.9, ";
  if (text.find(cfl) != std::string::npos) text.erase(text.find(cfl), cfl.size());
  return text;
}

// Table 5.1's Stokes row at 40 x 160 as the steady state (three steps of 100 s): -0.35402 m/s with
// the thesis's coupling faces (+1.1 % against the analytic -0.35011); -0.33980 with the walls at the
// surface (-2.9 %: the staircase's buoyancy is 1.9 % too large, 80 cells for the disk's 78.5);
// -0.34623 (-1.1 %) with the body's own volume for the buoyancy too. docs/benchmarks_fsi.md.
TEST(FsiFallingCylinder, SteadyStokesSpeedAt40x160) {
  const Registry registry = builtins();
  const std::string text = cylinderWithoutCfl();
  ASSERT_EQ(text.find("cfl"), std::string::npos);
  const double analytic = -0.35011;
  const struct {
    std::string wall, buoyancy;
    double speed, tolerance;
  } cases[] = {{"face", "structure_cells", -0.35402, 0.015},
               {"surface", "structure_cells", -0.33980, 0.03},
               {"surface", "body_volume", -0.34623, 0.015}};
  for (const auto& c : cases) {
    Simulation<2> sim(parseScene(text, "falling_cylinder.json",
                                 {{"solvers.fluid.advection", "none"}, {"solvers.fluid.obstacle_wall", c.wall},
                                  {"entities.fluid.fsi_solver.buoyancy", c.buoyancy},
                                  {"time.dt", "100"}, {"time.end", "300"}}),
                      registry, 2);
    std::map<std::string, double> m, previous;
    while (!sim.finished()) {
      previous = m;
      m = sim.step();
    }
    const double v = m.at("fsi_cylinder_velocity_y");
    EXPECT_NEAR(v, c.speed, 2e-5) << c.wall << " " << c.buoyancy;
    EXPECT_LT(std::abs(v / analytic - 1), c.tolerance) << c.wall << " " << c.buoyancy;
    EXPECT_LT(std::abs(v - previous.at("fsi_cylinder_velocity_y")), 1e-5) << c.wall << " " << c.buoyancy;
  }
}

// A neutrally buoyant cylinder (rho_s = rho_f) at 20 x 80 (radius 2.5 cells: 16 structure cells for
// the disk's 19.6): with "buoyancy": "body_volume" it stays at rest in the fluid at rest; with the
// staircase's buoyancy (default) it sinks, the 3.6 cells' fluid weight short of its own (measured
// -0.012 m/s against 5e-7).
TEST(FsiFallingCylinder, NeutrallyBuoyantBodyStaysAtRestWithItsOwnVolume) {
  const Registry registry = builtins();
  const std::string text = cylinderWithoutCfl();
  double speed[2] = {0, 0};
  for (int bodyVolume = 0; bodyVolume < 2; ++bodyVolume) {
    Simulation<2> sim(parseScene(text, "falling_cylinder.json",
                                 {{"entities.fluid.mac_grid.cells", "[20,80]"},
                                  {"entities.cylinder.rigid_body.mass", "0.078539816339744831"},
                                  {"solvers.fluid.advection", "none"},
                                  {"entities.fluid.fsi_solver.buoyancy", bodyVolume ? "body_volume" : "structure_cells"},
                                  {"time.dt", "100"}, {"time.end", "200"}}),
                      registry, 1);
    while (!sim.finished()) speed[bodyVolume] = sim.step().at("fsi_cylinder_velocity_y");
  }
  EXPECT_LT(speed[0], -0.01) << speed[0];
  EXPECT_LT(std::abs(speed[1]), 1e-3 * std::abs(speed[0])) << speed[1];  // the CG tolerance's residue
}

// Sec. 5.8 stability: the cylinder's mass scaled by 1e-9 (it rises to the top, carried by buoyancy) and by
// 1e9 (it falls freely: the fluid's force is 1e-9 of its weight) runs 200 steps without blowing up.
TEST(FsiFallingCylinder, ExtremeMassRatiosStayStable) {
  const Registry registry = builtins();
  const double mass = 2e3 * M_PI * 25e-6;
  for (double scale : {1e-9, 1e9}) {
    char value[40];
    std::snprintf(value, sizeof value, "%.17g", scale * mass);
    Simulation<2> sim(loadScene(kScenes + "falling_cylinder.json",
                                {{"entities.fluid.mac_grid.cells", "[20,80]"},
                                 {"entities.cylinder.rigid_body.mass", value},
                                 {"time.end", "10"}}),
                      registry, 2);
    double maxEnergyChange = -1e300, time = 0, fastestRise = -1e300;
    for (int step = 0; step < 200; ++step) {
      const auto& m = sim.step();
      time = sim.time();
      fastestRise = std::max(fastestRise, m.at("fsi_cylinder_velocity_y"));
      ASSERT_TRUE(std::isfinite(m.at("fsi_cylinder_velocity_y"))) << "scale " << scale << " step " << step;
      ASSERT_TRUE(std::isfinite(m.at("fluid_kinetic_energy"))) << "scale " << scale << " step " << step;
      maxEnergyChange = std::max(maxEnergyChange, m.at("fsi_energy_change"));
    }
    const RigidBody<2>& body = bodyNamed(sim, "cylinder");
    const auto& grid = sim.world().pool<MacGrid<2>>().components()[0];
    double umax = 0;
    for (double u : grid.u) umax = std::max(umax, std::abs(u));
    if (scale > 1) {
      EXPECT_NEAR(body.v.y(), -9.8 * time, 1e-3 * 9.8 * time);  // free fall
    } else {
      // Buoyancy lifts a massless cylinder at a Stokes-like speed (0.35 m/s for the same net
      // force; measured 0.27 m/s) until it reaches the outflow at the top (t ~ 0.25 s), where it
      // stays.
      EXPECT_GT(fastestRise, 0.1);
      EXPECT_LT(fastestRise, 1.0);
      EXPECT_GT(body.x.y(), 0.155);
    }
    EXPECT_LT(umax, scale > 1 ? 20.0 : 2.0) << "scale " << scale;
    EXPECT_LE(maxEnergyChange, 1e-9) << "scale " << scale;
  }
}

// Stokes flow (advection "none", Sec. 5.7): no half-step solve and no structure advection: the
// cylinder stays where it is and picks up speed downwards.
TEST(FsiFallingCylinder, StokesModeKeepsTheStructureInPlace) {
  const Registry registry = builtins();
  Simulation<2> sim(loadScene(kScenes + "falling_cylinder.json", {{"entities.fluid.mac_grid.cells", "[20,80]"},
                                                                   {"solvers.fluid.advection", "none"},
                                                                   {"time.end", "0.04"}}),
                    registry, 1);
  std::map<std::string, double> last;
  while (!sim.finished()) last = sim.step();
  const RigidBody<2>& body = bodyNamed(sim, "cylinder");
  EXPECT_EQ(body.x, Eigen::Vector2d(0.02, 0.12));
  EXPECT_LT(body.v.y(), -0.05);
  EXPECT_EQ(last.count("fsi_half_step_iterations"), 0u);
}

// 1 and 2 threads: bitwise identical bodies and fluid.
TEST(FsiFallingCylinder, OneAndTwoThreadsAgreeBitwise) {
  const Registry registry = builtins();
  auto run = [&](int threads) {
    Simulation<2> sim(loadScene(kScenes + "falling_cylinder.json",
                                {{"entities.fluid.mac_grid.cells", "[20,80]"}, {"time.end", "0.06"}}),
                      registry, threads);
    while (!sim.finished()) sim.step();
    const RigidBody<2>& b = bodyNamed(sim, "cylinder");
    std::vector<double> state = {b.x.x(), b.x.y(), b.v.x(), b.v.y(), b.L[0], b.orientation};
    const auto& grid = sim.world().pool<MacGrid<2>>().components()[0];
    state.insert(state.end(), grid.u.begin(), grid.u.end());
    state.insert(state.end(), grid.p.begin(), grid.p.end());
    return state;
  };
  const std::vector<double> one = run(1), two = run(2);
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i) ASSERT_EQ(one[i], two[i]) << "entry " << i;
  EXPECT_LT(one[3], -0.01);  // it did fall
}

// Bad scenes: fluid_coupling needs a dynamic or static rigid body, not both couplings on one body.
TEST(FsiScene, BadCouplingIsRefusedWithItsPath) {
  const Registry registry = builtins();
  const std::string head = R"({"dimension": 2, "time": {"dt": 0.01, "end": 0.1}, "entities": [
    {"name": "fluid", "mac_grid": {"cells": [8, 8], "domain_min": [0, 0], "domain_max": [1, 1]}},
    {"name": "disk", "shape": {"type": "disk", "radius": 0.2}, )";
  const struct {
    std::string body, expected;
  } cases[] = {{R"("rigid_body": {"mass": 1, "position": [0.5, 0.5]}, "kinematic": {"schedule": [{"velocity": [0, 1]}]},
                   "fluid_coupling": {}}]})",
                "kinematic rigid_body"},
               {R"("rigid_body": {"position": [0.5, 0.5]}, "fluid_obstacle": {}, "fluid_coupling": {}}]})", ""},
               {R"("rigid_body": {"position": [0.5, 0.5]}, "fluid_coupling": {"mass": 3}}]})", "mass"}};
  for (const auto& c : cases) {
    World<2> world;
    try {
      populateWorld(parseScene(head + c.body, "bad_fsi.json"), registry, world);
      ADD_FAILURE() << "accepted: " << c.body;
    } catch (const SceneError& e) {
      EXPECT_EQ(e.file(), "bad_fsi.json");
      EXPECT_NE(e.path().find("entities[1]"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos) << e.what();
    }
  }
  // An unknown buoyancy on the fluid's fsi_solver.
  const std::string bad = R"({"dimension": 2, "time": {"dt": 0.01, "end": 0.1}, "entities": [
    {"name": "fluid", "mac_grid": {"cells": [8, 8], "domain_min": [0, 0], "domain_max": [1, 1]},
     "fsi_solver": {"buoyancy": "archimedes"}}]})";
  try {
    World<2> world;
    populateWorld(parseScene(bad, "bad_fsi.json"), registry, world);
    ADD_FAILURE() << "accepted buoyancy \"archimedes\"";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.file(), "bad_fsi.json");
    EXPECT_NE(e.path().find("entities[0]"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("body_volume"), std::string::npos) << e.what();
  }
}

// 3-D: a sphere two-way coupled in a closed box (6 DOFs per body): it sinks, its force columns
// carry the buoyancy and drag, no solve adds kinetic energy, and it does not start spinning.
TEST(FsiSphere3D, HeavySphereSinksWithoutEnergyGain) {
  const Registry registry = builtins();
  const std::string text = R"({"dimension": 3, "gravity": [0, 0, -9.8], "time": {"dt": 0.005, "steps": 12},
    "solvers": {"fluid": {"advection": "semi_lagrangian"}},
    "entities": [
      {"name": "fluid", "mac_grid": {"cells": [10, 10, 14], "domain_min": [0, 0, 0], "domain_max": [1, 1, 1.4],
                                     "boundaries": {"z_max": {"type": "outflow"}}},
       "fluid_material": {"density": 1, "viscosity": 0.05}},
      {"name": "ball", "shape": {"type": "sphere", "radius": 0.25},
       "rigid_body": {"mass": 0.2, "position": [0.5, 0.5, 0.8]}, "fluid_coupling": {}}]})";
  Simulation<3> sim(parseScene(text, "sphere_3d.json"), registry, 2);
  double maxEnergyChange = -1e300;
  std::map<std::string, double> m;
  while (!sim.finished()) {
    m = sim.step();
    maxEnergyChange = std::max({maxEnergyChange, m.at("fsi_energy_change"), m.at("fsi_half_step_energy_change")});
  }
  const auto& body = *sim.world().get<RigidBody<3>>(*sim.world().find("ball"));
  const double t = sim.time(), volume = 4.0 / 3.0 * M_PI * 0.25 * 0.25 * 0.25;
  EXPECT_LT(body.v.z(), 0.0);
  // Slower than free fall: buoyancy (the displaced fluid weighs 0.065 of its 0.2 kg) and drag.
  EXPECT_GT(body.v.z(), -9.8 * t * (1 - 0.5 * volume / 0.2));
  EXPECT_GT(m.at("fsi_ball_force_z"), 0.0);
  EXPECT_LT(std::abs(body.v.x()) + std::abs(body.v.y()), 1e-6 * std::abs(body.v.z()) + 1e-12);
  EXPECT_LT(body.omega().norm(), 1e-6);
  EXPECT_LE(maxEnergyChange, 1e-12);
  EXPECT_GT(m.at("fsi_coupling_faces"), 50.0);
}

// falling_sphere as shipped (a circular tube, 16 x 16 x 32 cells, radius 2 cells, the walls at the
// surfaces, the sphere's own volume for its buoyancy, dt = 1 s: the steady Stokes state is the
// step's fixed point): within 10 % of Stokes' law with the Haberman-Sayre factor (measured 4.0 % fast), steady after three solves, and the
// coupling impulses carry the sphere's weight. The error follows the staircase sphere's volume,
// which jumps with r / dx (docs/benchmarks_fsi.md: -5.3 ... +4.2 % from 16 to 32 cells).
TEST(FsiFallingSphere, SteadyStokesSpeedWithinTenPercentOfHabermanSayre) {
  const Registry registry = builtins();
  Simulation<3> sim(loadScene(kScenes + "falling_sphere.json", {{"time.end", "3"}}), registry, 2);
  std::map<std::string, double> m, previous;
  while (!sim.finished()) {
    previous = m;
    m = sim.step();
  }
  const double v = m.at("fsi_sphere_velocity_z"), reference = -0.02881;
  EXPECT_NEAR(v, -0.029952, 2e-5);
  EXPECT_LT(std::abs(v / reference - 1), 0.10) << v;
  EXPECT_LT(std::abs(v - previous.at("fsi_sphere_velocity_z")), 1e-6);
  // The fluid carries the weight less the buoyancy correction: (m - rho_f (V - V_cells)) g with the
  // 32 structure cells of 1 mm^3 against the sphere's 33.5 mm^3.
  const double volume = 4.0 / 3.0 * M_PI * 8e-9, weight = (2.6138050877411896e-4 - 1260 * (volume - 32e-9)) * 9.81;
  EXPECT_NEAR(m.at("fsi_sphere_force_z"), weight, 1e-3 * weight);
}

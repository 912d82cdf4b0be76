// Obstacles in the MAC grid fluid (fluid_obstacle, rasterize_obstacles, obstacle_forces):
// the staircase rasterization of a disk, the drag and lift on the DFG 2D-1 cylinder after a
// short run, and the force columns in the CLI's metrics.csv.
#include <gtest/gtest.h>

#include "support/scenes.h"

#include <cmath>

#include "components/mac_grid.h"
#include "scenarios/simulation.h"
#include "solvers/mac_layout.h"
#include "support/cli_harness.h"
#include "support/uniform_stream.h"
#include "systems/fluid_obstacles.h"

using namespace monolith;
using namespace monolith::test;

namespace {
using test::builtins;
using test::kScenes;

const MacGrid<2>& gridOf(Simulation<2>& sim) { return sim.world().pool<MacGrid<2>>().components()[0]; }
}  // namespace

TEST(FluidObstacles, DiskRasterizesToItsAreaAndNothingOutside) {
  const Registry registry = builtins();
  // The staircase rasterization (the thesis' Sec. 5.4.1); the scene itself cuts faces.
  Simulation<2> sim(loadScene(kScenes + "dfg_2d1.json", {{"solvers.fluid.obstacle_cells", "staircase"}}), registry, 1);
  const MacGrid<2>& grid = gridOf(sim);
  const std::vector<std::uint8_t> mask = obstacleMask(sim.world(), grid);
  const solvers::MacLayout<2> layout(grid.cells, grid.dx, grid.origin);
  const Eigen::Vector2d centre(0.2, 0.2);
  const double r = 0.05;
  int count = 0;
  for (int c = 0; c < layout.cellCount(); ++c) {
    const double dist = (layout.cellCenter(layout.cellCoord(c)) - centre).norm();
    if (mask[c]) {
      ++count;
      EXPECT_LE(dist, r + 1e-12) << "cell " << c << " marked outside the disk";
    } else {
      EXPECT_GT(dist, r - 1e-12) << "cell " << c << " inside the disk not marked";
    }
  }
  // pi r^2 / dx^2 = 78.5 cells; the lattice count of centres in a disk of radius 5 cells differs
  // from the area by O(perimeter / dx) in the worst case but only by a few cells here. A missing
  // rotation/offset (e.g. centres at integer multiples of dx) changes the count by >= 4.
  EXPECT_NEAR(count, M_PI * r * r / (grid.dx * grid.dx), 4.0);

  // One step: the system writes exactly this mask into the grid.
  sim.step();
  EXPECT_EQ(gridOf(sim).solid, mask);
}

TEST(FluidObstacles, CylinderDragIsPositiveAndLiftSmall) {
  // DFG 2D-1 at dx = 0.01 run to t = 1 (40 steps; the force is then within 0.5 % of its
  // steady value, measured). Reference c_D = 5.58; the steady value at this resolution is 5.77
  // (the thesis's staircase and face wall, semi-Lagrangian: the set-up run here; the scene's own
  // cut faces are tested in DfgSteady) and 6.03 (wall at the surface), measured,
  // so [0.85, 1.2] x reference fails for a sign error, a missing pressure or shear term (each
  // changes c_D by > 30 %) or a wrong area scaling.
  const Registry registry = builtins();
  Simulation<2> sim(loadScene(kScenes + "dfg_2d1.json", {{"time.end", "1.0"},
                                                         {"solvers.fluid.obstacle_cells", "staircase"},
                                                         {"solvers.fluid.obstacle_wall", "face"},
                                                         {"solvers.fluid.advection", "semi_lagrangian"}}),
                    registry, 2);
  double fx = 0, fy = 0;
  while (!sim.finished()) {
    const auto& diag = sim.step();
    fx = diag.at("obstacle_cylinder_force_x");
    fy = diag.at("obstacle_cylinder_force_y");
  }
  const double cD = 2 * fx / (0.2 * 0.2 * 0.1), cL = 2 * fy / (0.2 * 0.2 * 0.1);
  std::printf("dfg_2d1 dx = 0.01, t = %.2f: c_D = %.4f, c_L = %.5f\n", sim.time(), cD, cL);
  EXPECT_GT(cD, 0.85 * 5.5795);
  EXPECT_LT(cD, 1.2 * 5.5795);
  // Reference c_L = 0.0106 (0.2 % of c_D); the staircase is not exactly symmetric about y = 0.2
  // either, so only demand |lift| below 5 % of the drag.
  EXPECT_LT(std::abs(cL), 0.05 * cD);
}

TEST(FluidObstacles, ForceColumnsAreInTheCliMetrics) {
  TempDir tmp;
  const std::string out = (tmp.path() / "run").string();
  const CommandResult r = run({MONOLITH_CLI, "run", kScenes + "dfg_2d1.json", "--out", out, "--set", "time.end=0.5",
                               "--no-frames", "--quiet", "--threads", "1"},
                              tmp.logs());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto rows = lines(slurp(tmp.path() / "run" / "metrics.csv"));
  ASSERT_GE(rows.size(), 2u);
  std::vector<std::string> header;
  {
    std::stringstream ss(rows[0]);
    for (std::string cell; std::getline(ss, cell, ',');) header.push_back(cell);
  }
  std::vector<double> last;
  {
    std::stringstream ss(rows.back());
    for (std::string cell; std::getline(ss, cell, ',');) last.push_back(std::stod(cell));
  }
  ASSERT_EQ(header.size(), last.size());
  int fxColumn = -1, fyColumn = -1;
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] == "obstacle_cylinder_force_x") fxColumn = int(i);
    if (header[i] == "obstacle_cylinder_force_y") fyColumn = int(i);
  }
  ASSERT_GE(fxColumn, 0) << rows[0];
  ASSERT_GE(fyColumn, 0) << rows[0];
  // At t = 0.5 (20 steps) the drag is already of its steady order (measured F_x = 0.0114 against
  // the steady 0.0118 at dx = 0.01): positive and within a factor 2 of 0.0112; the lift is small.
  EXPECT_GT(last[fxColumn], 0.5 * 0.0112);
  EXPECT_LT(last[fxColumn], 2.0 * 0.0112);
  EXPECT_LT(std::abs(last[fyColumn]), 0.05 * last[fxColumn]);
}

// --- kinematic obstacles: faces covered by a moving body carry its rigid velocity (Sec. 5.4.1) ---

namespace {
Simulation<2> kinematicScene(const std::string& text, const Registry& registry) {
  return Simulation<2>(parseScene(text, "kinematic_obstacle.json"), registry, 1);
}
}  // namespace

TEST(KinematicObstacles, BoxMovingWithAUniformStreamLeavesItUndisturbed) {
  // A box carried along at the stream's own speed: every face it covers or uncovers carries
  // u = (1, 0), so the exact solution is the uniform stream and the fluid pushes on nothing.
  // Stale velocities on uncovered faces, a wall velocity of 0 instead of the body's, or a
  // shear computed against a wall at rest each break this by O(1).
  // The thesis's staircase (the default cells).
  const StreamResult r = uniformStream(
      R"("shape": { "type": "box", "half_extents": [0.2, 0.15] }, "rigid_body": { "mass": 1, "position": [0.6, 0.5] })",
      "staircase");
  EXPECT_NEAR(r.finalPosition.x(), 0.9, 1e-12);  // it did move 0.3 = 6 cells
  EXPECT_LT(r.worstVelocityError, 1e-8);
  EXPECT_LT(r.worstForce, 1e-8);
}

TEST(KinematicObstacles, SpinningDiskCarriesItsRigidVelocityAndDragsTheFluidAround) {
  // A disk spinning counter-clockwise at 1 rad/s in a closed box of fluid at rest.
  const Registry registry = builtins();
  Simulation<2> sim = kinematicScene(R"({
    "dimension": 2, "time": { "dt": 0.02, "end": 0.4 },
    "entities": [
      { "name": "fluid",
        "mac_grid": { "cells": [40, 40], "domain_min": [-1, -1], "domain_max": [1, 1],
                      "boundaries": { "x_min": { "type": "wall" }, "x_max": { "type": "wall" },
                                      "y_min": { "type": "wall" }, "y_max": { "type": "wall" } } },
        "fluid_material": { "density": 1, "viscosity": 0.1 } },
      { "name": "disk", "shape": { "type": "disk", "radius": 0.4 },
        "rigid_body": { "mass": 1, "position": [0, 0] },
        "kinematic": { "angular_velocity": 1 }, "fluid_obstacle": {} } ] })",
                                     registry);
  Eigen::Vector2d force = Eigen::Vector2d::Zero();
  while (!sim.finished()) {
    const auto& diag = sim.step();
    force = Eigen::Vector2d(diag.at("obstacle_disk_force_x"), diag.at("obstacle_disk_force_y"));
  }
  const MacGrid<2>& grid = gridOf(sim);
  const solvers::MacLayout<2> layout(grid.cells, grid.dx, grid.origin);
  // 1. Every face with a solid cell on either side carries the normal component of w x r at its
  //    centre, exactly (the equal-velocity constraint at face centres).
  const auto touchesSolid = [&](int axis, solvers::MacLayout<2>::Index index) {
    const bool upper = layout.cellInside(index) && grid.solid[layout.cellIndex(index)];
    index[axis] -= 1;
    return upper || (layout.cellInside(index) && grid.solid[layout.cellIndex(index)]);
  };
  int constrained = 0;
  double worstConstraint = 0;
  for (int f = 0; f < layout.totalFaces(); ++f) {
    const auto [axis, index] = layout.faceCoord(f);
    if (!touchesSolid(axis, index)) continue;
    const Eigen::Vector2d x = layout.faceCenter(axis, index);
    const Eigen::Vector2d rigid(-x.y(), x.x());  // w x r with w = 1
    worstConstraint = std::max(worstConstraint, std::abs(grid.u[f] - rigid[axis]));
    ++constrained;
  }
  EXPECT_GT(constrained, 400);  // about pi (0.4 / 0.05)^2 cells, 2 faces each
  EXPECT_LT(worstConstraint, 1e-12);
  // 2. The fluid is dragged counter-clockwise: positive angular momentum about the centre.
  double angular = 0;
  for (int f = 0; f < layout.totalFaces(); ++f) {
    const auto [axis, index] = layout.faceCoord(f);
    if (touchesSolid(axis, index)) continue;
    const Eigen::Vector2d x = layout.faceCenter(axis, index);
    angular += axis == 0 ? -x.y() * grid.u[f] : x.x() * grid.u[f];
  }
  EXPECT_GT(angular * grid.dx * grid.dx, 1e-3);
  // 3. By the 4-fold symmetry of the staircase disk in the box the net force vanishes.
  EXPECT_LT(force.norm(), 1e-8);
}

// --- where the viscous operator puts an obstacle's wall ("obstacle_wall": surface | face | cell_boundary) ---

TEST(ObstacleWall, DiskWallDistancesAreTheRayHitsOfTheCircle) {
  // With "obstacle_wall": "surface", every free face whose neighbour face along some axis is an
  // obstacle face gets the distance to the circle along that ray (in cells, clamped to [0.1, 1]).
  // Checked against the closed-form hit of x + t e with |x + t e - c| = r.
  const Registry registry = builtins();
  Simulation<2> sim(loadScene(kScenes + "dfg_2d1.json", {{"solvers.fluid.obstacle_cells", "staircase"}}), registry, 1);
  sim.step();
  const MacGrid<2>& grid = gridOf(sim);
  const solvers::MacLayout<2> layout(grid.cells, grid.dx, grid.origin);
  ASSERT_EQ(grid.obstacleWallDistance.size(), static_cast<std::size_t>(layout.totalFaces()) * 4);
  const Eigen::Vector2d centre(0.2, 0.2);
  const double r = 0.05;
  int surfaceRows = 0;
  for (int g = 0; g < layout.totalFaces(); ++g) {
    const auto [a, f] = layout.faceCoord(g);
    for (int b = 0; b < 2; ++b)
      for (int dir = -1; dir <= 1; dir += 2) {
        const double theta = grid.obstacleWallDistance[4 * g + 2 * b + (dir > 0)];
        if (theta == 1.0) continue;
        ++surfaceRows;
        const Eigen::Vector2d x = layout.faceCenter(a, f) - centre;
        // |x + t dir e_b|^2 = r^2 -> t = -dir x_b - sqrt(r^2 - x_other^2) (the nearer root)
        const double t = -dir * x[b] - std::sqrt(r * r - x[1 - b] * x[1 - b]);
        EXPECT_NEAR(theta, std::max(t / grid.dx, 0.1), 1e-12) << "face " << g << " axis " << b << " direction " << dir;
      }
  }
  std::printf("rows ending on the circle within a cell: %d\n", surfaceRows);
  EXPECT_EQ(surfaceRows, 44);  // 28 tangential rows and 16 along the faces' own axes
}

namespace {
// Plane Couette flow (Stokes, mu = 1) between a lid at y = 1 moving at U = 1 and a static box
// obstacle filling the bottom up to y_w = 0.237, which is not on a cell boundary (dx = 0.05:
// the solid rows end at y = 0.25, their top u-faces at y = 0.225). x is periodic. Returns the
// largest deviation of the u-faces above the box from U (y - wall) / (1 - wall), and the x force
// on the box against mu U L / (1 - wall) (L = 0.5), relative.
std::pair<double, double> couetteOverBox(const std::string& obstacleWall, double wall) {
  const Registry registry = builtins();
  Simulation<2> sim(parseScene(R"({
    "dimension": 2, "time": { "dt": 1.0, "end": 30 },
    "solvers": { "fluid": { "advection": "none", "tolerance": 1e-12, "obstacle_wall": ")" + obstacleWall + R"(" } },
    "entities": [
      { "name": "fluid",
        "mac_grid": { "cells": [10, 20], "domain_min": [0, 0], "domain_max": [0.5, 1],
                      "boundaries": { "x_min": { "type": "periodic" }, "x_max": { "type": "periodic" },
                                      "y_min": { "type": "wall" }, "y_max": { "type": "wall", "velocity": [1, 0] } } },
        "fluid_material": { "density": 1, "viscosity": 1 } },
      { "name": "floor", "shape": { "type": "box", "half_extents": [1.0, 0.1185] },
        "rigid_body": { "mass": 1, "position": [0.25, 0.1185], "static": true }, "fluid_obstacle": {} } ] })",
                               "couette_over_box.json"),
                    registry, 1);
  double fx = 0;
  while (!sim.finished()) fx = sim.step().at("obstacle_floor_force_x");
  const MacGrid<2>& grid = gridOf(sim);
  const solvers::MacLayout<2> layout(grid.cells, grid.dx, grid.origin, {true, false});
  double worst = 0;
  for (int g = 0; g < layout.totalFaces(); ++g) {
    const auto [a, f] = layout.faceCoord(g);
    const Eigen::Vector2d x = layout.faceCenter(a, f);
    if (a != 0 || x.y() < 0.25) continue;  // u-faces in fluid cells
    worst = std::max(worst, std::abs(grid.u[g] - (x.y() - wall) / (1 - wall)));
  }
  return {worst, std::abs(fx / (0.5 / (1 - wall)) - 1)};
}
}  // namespace

TEST(ObstacleWall, SurfaceWallGivesTheExactCouetteProfileAndShear) {
  // With the wall at the body's surface (theta = 0.76 cells below the first u-face) the linear
  // profile is an exact solution of the discrete equations, and the force is the momentum the
  // shear rows hand to the body: both to solver precision.
  const auto [profile, force] = couetteOverBox("surface", 0.237);
  EXPECT_LT(profile, 1e-8);
  EXPECT_LT(force, 1e-8);
}

namespace {
// The Couette flow of `mode` is exact (to solver precision) for a wall at `exactWall` and
// measurably off for the body's true surface at 0.237.
void expectExactOnlyFor(const std::string& mode, double exactWall) {
  const auto [profile, force] = couetteOverBox(mode, exactWall);
  EXPECT_LT(profile, 1e-8) << mode;
  EXPECT_LT(force, 1e-8) << mode;
  const auto [offProfile, offForce] = couetteOverBox(mode, 0.237);
  EXPECT_GT(offForce, 0.01) << mode;
  EXPECT_GT(offProfile, 1e-3) << mode;
}
}  // namespace

TEST(ObstacleWall, CellBoundaryWallIsTheStaircasesOwnBoundary) {
  // "cell_boundary": the wall sits where the solid cells end (y = 0.25, half a cell below the
  // first u-faces), where a finite-volume code on the same staircase has it: exact there, and off
  // the true wall by 0.013 (about 1.7 % of the slope).
  expectExactOnlyFor("cell_boundary", 0.25);
}

TEST(ObstacleWall, FaceWallIsTheThesisStaircase) {
  // "face": the wall sits at the solid row's u-face centres (y = 0.225), exactly as the thesis's
  // first-order constraint places it; the profile and force are exact for that wall instead, and
  // off the true one by the 0.012 offset (about 1.6 % of the slope).
  expectExactOnlyFor("face", 0.225);
}

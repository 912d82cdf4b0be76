// Cut faces at obstacles ("obstacle_cells": "cut", solvers::cutFaces): the open fractions are the
// exact chords of a disk, a body moving with a uniform stream leaves it exact, and the pressure
// impulse of a suddenly started disk (2-D) and sphere (3-D) is the potential-flow added mass.
#include <gtest/gtest.h>

#include "support/scenes.h"
#include "support/started_obstacle.h"
#include "support/uniform_stream.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "components/mac_grid.h"
#include "scenarios/simulation.h"
#include "solvers/mac_layout.h"
#include "systems/fluid_obstacles.h"

using namespace monolith;
using namespace monolith::test;

namespace {
using test::builtins;

template <int d>
const MacGrid<d>& gridOf(Simulation<d>& sim) {
  return sim.world().template pool<MacGrid<d>>().components()[0];
}

}  // namespace

TEST(CutCells, OpenFractionsAreTheExactChordsOfTheDisk) {
  // A disk of radius 3.3 cells off the grid's nodes: every face's open fraction is 1 minus its
  // chord through the circle over dx (fractions under 1 % count as covered), and exactly the cells
  // whose faces are all covered are solid.
  const Registry registry = builtins();
  Simulation<2> sim(parseScene(R"({ "dimension": 2, "time": { "dt": 0.01, "end": 0.01 },
    "solvers": { "fluid": { "obstacle_cells": "cut" } },
    "entities": [
      { "name": "fluid", "mac_grid": { "cells": [16, 12], "domain_min": [0, 0], "domain_max": [1.6, 1.2],
                                       "boundaries": { "x_min": { "type": "wall" }, "x_max": { "type": "wall" },
                                                       "y_min": { "type": "wall" }, "y_max": { "type": "wall" } } },
        "fluid_material": { "density": 1, "viscosity": 0.01 } },
      { "name": "disk", "shape": { "type": "disk", "radius": 0.33 },
        "rigid_body": { "static": true, "position": [0.817, 0.561] }, "fluid_obstacle": {} } ] })",
                               "cut_disk.json"),
                    registry, 1);
  sim.step();
  const MacGrid<2>& grid = gridOf(sim);
  const solvers::MacLayout<2> layout(grid.cells, grid.dx, grid.origin);
  ASSERT_EQ(static_cast<int>(grid.openFraction.size()), layout.totalFaces());
  const Eigen::Vector2d centre(0.817, 0.561);
  const double r = 0.33, h = grid.dx;
  int cut = 0;
  for (int g = 0; g < layout.totalFaces(); ++g) {
    const auto [a, f] = layout.faceCoord(g);
    const Eigen::Vector2d x = layout.faceCenter(a, f);
    const int t = 1 - a;
    const double across = x[a] - centre[a], half = r * r - across * across;
    double chord = 0;
    if (half > 0) {
      const double s = std::sqrt(half);
      chord = std::max(0.0, std::min(x[t] + h / 2, centre[t] + s) - std::max(x[t] - h / 2, centre[t] - s));
    }
    double open = 1 - chord / h;
    if (open < 0.01) open = 0;
    cut += open > 0 && open < 1;
    EXPECT_NEAR(grid.openFraction[g], open, 1e-12) << "face " << g;
  }
  EXPECT_GT(cut, 20);  // the test sees real cut faces (about 2 pi r / h of them)
  for (int c = 0; c < layout.cellCount(); ++c) {
    const auto ci = layout.cellCoord(c);
    bool allCovered = true;
    for (int a = 0; a < 2; ++a)
      for (int side = 0; side < 2; ++side) {
        auto f = ci;
        f[a] += side;
        allCovered = allCovered && grid.openFraction[layout.faceIndex(a, f)] == 0;
      }
    EXPECT_EQ(grid.solid[c] != 0, allCovered) << "cell " << c;
  }
}

TEST(CutCells, BodyMovingWithAUniformStreamLeavesItUndisturbed) {
  // With cut faces the open part of a face moves with the fluid and the covered part with the
  // body; when both move at (1, 0) the uniform stream is exact and the body feels no force.
  const StreamResult r = uniformStream(
      R"("shape": { "type": "disk", "radius": 0.17 }, "rigid_body": { "mass": 1, "position": [0.613, 0.488] })", "cut");
  EXPECT_GT(r.cutFaces, 10);
  EXPECT_LT(r.worstVelocityError, 1e-8);
  EXPECT_LT(r.worstForce, 1e-8);
}

namespace {
// Runs startedObstacle with cut faces and with the staircase; the cut added mass must be within
// `bound` of `exact` and at least twice as close as the staircase's.
template <int d>
void expectAddedMass(const std::string& cells, double half, const std::string& shape, const std::string& position,
                     double exact, double bound) {
  const auto [cut, cutDivergence] = startedObstacle<d>(cells, half, "\"shape\": " + shape, position, "cut");
  const auto [stair, stairDivergence] = startedObstacle<d>(cells, half, "\"shape\": " + shape, position, "staircase");
  std::printf("%d-D added mass / potential flow: cut %.5f, staircase %.5f\n", d, cut / exact, stair / exact);
  EXPECT_LT(cutDivergence, 1e-6);
  EXPECT_LT(stairDivergence, 1e-6);
  EXPECT_NEAR(cut / exact, 1.0, bound);
  EXPECT_GT(std::abs(stair / exact - 1), 2 * std::abs(cut / exact - 1));
}
}  // namespace

TEST(CutCells, StartedDiskPushesThePotentialFlowAddedMass) {
  // A disk (r = 0.1, 5 cells, off the nodes) started at U = 1 in a closed box of half-width 2:
  // the pressure impulse on it is -m_a U with the potential-flow added mass m_a = rho pi r^2 (the
  // box adds (r / L)^2-small confinement). Cut faces see the true circle; the staircase's
  // blocky body pushes a different mass. Measured: cut 0.991, staircase 1.038.
  expectAddedMass<2>("[200, 200]", 2.0, R"({ "type": "disk", "radius": 0.1 })", "[0.013, -0.007]", -M_PI * 0.1 * 0.1, 0.02);
}

TEST(CutCells, StartedSpherePushesThePotentialFlowAddedMass) {
  // 3-D: a sphere (r = 0.25, 5 cells) started at U = 1 in a closed box of half-width 1.6: m_a =
  // rho (2/3) pi r^3 (half the displaced mass), confinement O((r / L)^3). Measured: cut 0.987,
  // staircase 1.083.
  expectAddedMass<3>("[64, 64, 64]", 1.6, R"({ "type": "sphere", "radius": 0.25 })", "[0.013, -0.007, 0.021]",
                     -2.0 / 3.0 * M_PI * std::pow(0.25, 3), 0.03);
}

// Static obstacles in the MAC grid fluid (fluid_obstacle, rasterize_obstacles, obstacle_forces):
// the staircase rasterization of a disk, the drag and lift on the DFG 2D-1 cylinder after a
// short run, and the force columns in the CLI's metrics.csv.
#include <gtest/gtest.h>

#include "support/scenes.h"

#include <cmath>

#include "components/mac_grid.h"
#include "scenarios/simulation.h"
#include "solvers/mac_layout.h"
#include "support/cli_harness.h"
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
  Simulation<2> sim(loadScene(kScenes + "dfg_2d1.json"), registry, 1);
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
  // steady value, measured). Reference c_D = 5.58; the first-order staircase over-predicts it
  // by 6 % at this resolution (steady 5.90, measured),
  // so [0.85, 1.2] x reference fails for a sign error, a missing pressure or shear term (each
  // changes c_D by > 30 %) or a wrong area scaling.
  const Registry registry = builtins();
  Simulation<2> sim(loadScene(kScenes + "dfg_2d1.json", {{"time.end", "1.0"}}), registry, 2);
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

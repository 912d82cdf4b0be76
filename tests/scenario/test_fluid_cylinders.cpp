// Flow past cylinders (thesis Sec. 5.11.3-5.11.4, Schaefer & Turek 2D-2): the coupled
// pressure-viscosity solve and Chorin's splitting converge to each other, and shedding behind
// a cylinder has the published frequency, and the steady DFG 2D-1 forces are within 1 % (drag)
// and 3 % (lift) of the reference at 10 cells per diameter. The full-resolution runs are benchmarks
// (bench_cylinder_laminar, bench_vortex_shedding, bench_dfg 2d2); these are their coarse cousins.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "components/mac_grid.h"
#include "scenarios/fluid_fields.h"
#include "scenarios/simulation.h"
#include "support/oscillation.h"
#include "support/scenes.h"

using namespace monolith;
using namespace monolith::test;

namespace {

// Velocity at (3, 2.25) at t = 0.5 in cylinder_laminar at n x n cells, dt = dx / 2.
Eigen::Vector2d laminarSample(const Registry& registry, const std::string& projection, int n) {
  char dt[32];
  std::snprintf(dt, sizeof dt, "%.17g", 0.5 * 4.0 / n);
  Simulation<2> sim(loadScene(kScenes + "cylinder_laminar.json",
                              {{"entities.fluid.mac_grid.cells", "[" + std::to_string(n) + "," + std::to_string(n) + "]"},
                               {"solvers.fluid.projection", projection},
                               {"time.dt", dt}}),
                    registry, 2);
  while (!sim.finished()) sim.step();
  return sampleVelocity(sim.world().pool<MacGrid<2>>().components()[0], Eigen::Vector2d(3, 2.25));
}

}  // namespace

TEST(CylinderLaminar, CoupledSolveAndChorinConvergeToEachOther) {
  // Sec. 5.11.3: the sample is far from steady at t = 0.5, so this compares the dynamics. The
  // two schemes differ by O(dt) + O(dx) (first-order splitting and staircase); halving both must
  // bring them closer by about half. Measured: |coupled - Chorin| = 0.0235 at 40^2 and 0.0127 at
  // 80^2 (ratio 0.54); the sample itself is u = (0.47, -0.24) (Chorin, 160^2).
  const Registry registry = builtins();
  const double coarse = (laminarSample(registry, "coupled", 40) - laminarSample(registry, "chorin", 40)).norm();
  const Eigen::Vector2d coupled = laminarSample(registry, "coupled", 80), chorin = laminarSample(registry, "chorin", 80);
  const double fine = (coupled - chorin).norm();
  std::printf("|coupled - chorin|: %.4g at 40^2, %.4g at 80^2; coupled u(3, 2.25) = (%.4f, %.4f)\n", coarse, fine,
              coupled.x(), coupled.y());
  EXPECT_LT(fine, 0.65 * coarse);
  EXPECT_LT(fine, 0.02);
  // The wake behind the cylinder: slower than the inflow, deflected towards the axis y = 2.
  EXPECT_GT(coupled.x(), 0.3);
  EXPECT_LT(coupled.x(), 0.7);
  EXPECT_LT(coupled.y(), -0.1);
}

TEST(DfgSteady, CutFacesAndWeno5HitTheReferenceForcesAt10CellsPerDiameter) {
  // Schaefer & Turek 2D-1 (Re 20) at 220 x 41 (D = 10 cells) with cut faces, the no-slip wall at
  // the disk's surface and WENO5 advection, to t = 10: the forces are then steady to 0.03 %
  // (measured over the run to the 1e-6 stop criterion at t = 20.6, docs/benchmarks.md).
  // Measured c_D = 5.8443 (+4.7 %), c_L = 0.008906 (-16 %). The drag error is mostly the split
  // scheme's O(dt) error of the steady state (dt/2, dt/4: c_D +2.6 %, +1.5 %; extrapolated to
  // dt -> 0 +0.4 %; with the cut faces inside the disk as ordinary unknowns instead of its wall,
  // -3.9 %, which at this dt cancelled to +0.7 %). The lift bound fails if the boundary or the
  // advection regresses: the staircase (ENO3) gave c_L +41 %, semi-Lagrangian advection +57 %.
  const Registry registry = builtins();
  // These are the scene's own settings; spelled out so that the test keeps its meaning.
  Simulation<2> sim(loadScene(kScenes + "dfg_2d1.json", {{"time.end", "10.0"},
                                                         {"solvers.fluid.obstacle_cells", "cut"},
                                                         {"solvers.fluid.obstacle_wall", "surface"},
                                                         {"solvers.fluid.advection", "weno5"}}),
                    registry, 2);
  double fx = 0, fy = 0, change = 0;
  while (!sim.finished()) {
    const auto& diag = sim.step();
    fx = diag.at("obstacle_cylinder_force_x");
    fy = diag.at("obstacle_cylinder_force_y");
    change = diag.at("fluid_velocity_change");
  }
  const double cD = 2 * fx / (0.2 * 0.2 * 0.1), cL = 2 * fy / (0.2 * 0.2 * 0.1);  // rho = 1, Ubar = 0.2, D = 0.1
  std::printf("dfg_2d1 220x41 cut/surface/weno5 t = %.2f: c_D = %.4f (%+.2f %%), c_L = %.6f (%+.2f %%), max|du|/dt = %.2e\n",
              sim.time(), cD, 100 * (cD / 5.57953523384 - 1), cL, 100 * (cL / 0.010618948146 - 1), change);
  EXPECT_NEAR(cD, 5.57953523384, 0.05 * 5.57953523384);
  EXPECT_NEAR(cL, 0.010618948146, 0.2 * 0.010618948146);
  // Approaching the steady state smoothly (ENO3 stalls at 1.2e-3 in a limit cycle).
  EXPECT_LT(change, 1e-3);
}

namespace {
struct Shedding {
  Oscillation lift, drag;
  double strouhal;
};

// dfg_2d2.json with `overrides` to t = 6 on 2 threads; c_D, c_L and St analysed over t >= 3.
Shedding dfg2d2ToSixSeconds(const char* label, std::vector<Override> overrides) {
  overrides.insert(overrides.begin(), {"time.end", "6.0"});
  const Registry registry = builtins();
  Simulation<2> sim(loadScene(kScenes + "dfg_2d2.json", overrides), registry, 2);
  std::vector<double> t, cD, cL;
  while (!sim.finished()) {
    const auto& diag = sim.step();
    t.push_back(sim.time());
    cD.push_back(2 * diag.at("obstacle_cylinder_force_x") / 0.1);  // rho = 1, Ubar = 1, D = 0.1
    cL.push_back(2 * diag.at("obstacle_cylinder_force_y") / 0.1);
  }
  Shedding r{analyseOscillation(t, cL, 3.0), analyseOscillation(t, cD, 3.0), 0};
  r.strouhal = r.lift.frequency() * 0.1;
  std::printf("dfg_2d2 220x41%s t = 6: St = %.4f (%d periods), c_D max = %.4f, c_L max = %.4f\n", label, r.strouhal,
              r.lift.crossings - 1, r.drag.max, r.lift.max);
  return r;
}
}  // namespace

TEST(DfgPeriodic, VorticesShedAtNearlyTheReferenceFrequencyAt10CellsPerDiameter) {
  // Schaefer & Turek 2D-2 (Re 100) on the coarsest grid of the benchmark, 220 x 41 (D = 10
  // cells), to t = 6 s; the lift is analysed over t >= 3 s (the shedding is periodic from about
  // t = 3 s). Reference St = 0.300, c_D,max = 3.23, c_L,max = 1.00. Measured over t = 6-12 s at
  // this resolution with the scene's settings (MacCormack, cut faces, wall at the surface):
  // St = 0.2706 (-9.8 %), c_D,max = 3.468 (+7.4 %), c_L,max = 0.667 (to t = 6: 0.2708, 3.468,
  // 0.666). Before a cut face inside the disk was its wall for the viscous rows: St 0.277,
  // c_D,max 3.22 (-0.3 %), c_L,max 0.556, and 0.779 at 440 x 82 (docs/benchmarks.md). The
  // thesis's staircase disk gives 0.43 here, plain semi-Lagrangian advection 0.10: the lift bound
  // fails for either, the others if the shedding stops, its frequency moves by > 20 % or the
  // drag by > 10 %.
  const auto [lift, drag, st] = dfg2d2ToSixSeconds("", {});
  EXPECT_GE(lift.crossings, 6);
  EXPECT_NEAR(st, 0.300, 0.06);
  EXPECT_NEAR(drag.max, 3.23, 0.1 * 3.23);
  EXPECT_GT(lift.max, 0.5);
  EXPECT_LT(lift.max, 1.1);
}

TEST(DfgPeriodic, TheStaircasesOwnWallWithInsideGhostsLiftsMoreThanTheSceneAt10CellsPerDiameter) {
  // DFG 2D-2 as above on the staircase with the no-slip wall at the solid cells' boundary, for
  // the viscous rows and the advection's ghosts ("obstacle_wall": "cell_boundary",
  // "advection_wall": "surface"), the walls a finite-volume code has on that grid. Measured to
  // t = 6, over t >= 3 (docs/benchmarks.md, "The staircase's own wall"): c_L,max 0.697,
  // c_D,max 3.64, St 0.265. Ghosts also on the obstacle faces on the staircase's sides (the rule
  // before 2026-11-26) give 0.609 and 3.75, no ghosts 0.569 and 3.60, the scene 0.556 and 3.22:
  // both bounds below fail for the old rule, the lift bound without ghosts. This setting's lift
  // converges faster than the scene's (-9.0 % at 440 x 82, against -22.1 %), its drag pays
  // (+7.2 %, against -0.3 %).
  const auto [lift, drag, st] = dfg2d2ToSixSeconds(" staircase/cell_boundary/ghosts",
                                                   {{"solvers.fluid.obstacle_cells", "staircase"},
                                                    {"solvers.fluid.obstacle_wall", "cell_boundary"},
                                                    {"solvers.fluid.advection_wall", "surface"}});
  EXPECT_GE(lift.crossings, 6);
  EXPECT_NEAR(st, 0.265, 0.03);
  EXPECT_GT(lift.max, 0.66);
  EXPECT_LT(drag.max, 3.70);
  EXPECT_GT(drag.max, 3.23);  // the staircase disk is larger than the true one
}

TEST(VortexShedding, StrouhalNumberAtHalfTheThesisResolution) {
  // Sec. 5.11.4 at 200 x 80 cells (half the thesis's 400 x 160), dt = 0.04, to t = 80; the lift
  // is analysed over t >= 40 (the kinematic spin that breaks the symmetry stops at t = 1; the
  // street is periodic from about t = 30). The thesis measures St = 0.160 (its method) at
  // 400 x 160, the literature 0.164-0.173. Measured here: St = 0.150 (-6 %), c_L amplitude
  // 0.18. A 10 % band around 0.160 fails if the shedding stops, locks to another mode or the
  // obstacle force loses its sign conventions.
  const Registry registry = builtins();
  Simulation<2> sim(loadScene(kScenes + "vortex_shedding.json",
                              {{"entities.fluid.mac_grid.cells", "[200,80]"}, {"time.dt", "0.04"}, {"time.end", "80"}}),
                    registry, 2);
  std::vector<double> t, cL;
  while (!sim.finished()) {
    const auto& diag = sim.step();
    t.push_back(sim.time());
    cL.push_back(2 * diag.at("obstacle_cylinder_force_y"));  // rho = U = D = 1
  }
  const Oscillation lift = analyseOscillation(t, cL, 40.0);
  const double st = lift.frequency();
  std::printf("vortex_shedding 200x80: St = %.4f over %d periods, c_L amplitude %.3f\n", st, lift.crossings - 1,
              0.5 * (lift.max - lift.min));
  EXPECT_GE(lift.crossings, 5);
  EXPECT_NEAR(st, 0.160, 0.016);
  EXPECT_GT(0.5 * (lift.max - lift.min), 0.1);
  EXPECT_LT(std::abs(lift.mean), 0.02);  // symmetric shedding: no mean lift
}

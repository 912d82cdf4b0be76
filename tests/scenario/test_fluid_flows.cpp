// Incompressible flow scenes against analytic and published values (issue: MAC grid fluid):
// Poiseuille channel, decaying Taylor-Green vortex (convergence for both advection schemes),
// lid-driven cavity at Re 100 and (semi-Lagrangian vs MacCormack) Re 1000 against Ghia, Ghia &
// Shin (1982), and the high-viscosity channel
// where the coupled solve and Chorin's splitting are compared.
#include <gtest/gtest.h>

#include "support/scenes.h"

#include <chrono>
#include <cmath>

#include "components/mac_grid.h"
#include "scenarios/fluid_fields.h"
#include "scenarios/simulation.h"
#include "solvers/mac_layout.h"
#include "support/ghia.h"
#include "support/taylor_green.h"

using namespace monolith;

namespace {
using test::builtins;
using test::kScenes;

// Steps until the scene's "stop" diagnostic falls below its threshold (or the end).
template <int d>
void runToSteadyState(Simulation<d>& sim) {
  const auto& scene = sim.scene();
  while (!sim.finished()) {
    const auto& diag = sim.step();
    if (!scene.stopDiagnostic.empty() && diag.at(scene.stopDiagnostic) < scene.stopBelow) return;
  }
}

const MacGrid<2>& gridOf(Simulation<2>& sim) { return sim.world().pool<MacGrid<2>>().components()[0]; }
}  // namespace

TEST(Poiseuille, SteadyProfileIsParabolicWithinOnePercent) {
  const Registry registry = builtins();
  Simulation<2> sim(loadScene(kScenes + "poiseuille.json"), registry);
  runToSteadyState(sim);
  ASSERT_FALSE(sim.finished()) << "did not reach steady state before the end";
  const MacGrid<2>& grid = gridOf(sim);
  const solvers::MacLayout<2> layout(grid.cells, grid.dx, grid.origin);
  // Every x-face downstream of the inlet region (x >= 1): u(y) = 4 U y (1 - y).
  double worst = 0;
  for (int f = 0; f < layout.faceCount(0); ++f) {
    const auto [axis, index] = layout.faceCoord(f);
    const auto x = layout.faceCenter(axis, index);
    if (x.x() < 1.0) continue;
    worst = std::max(worst, std::abs(grid.u[f] - 4 * x.y() * (1 - x.y())));
  }
  EXPECT_LE(worst, 0.01) << "issue requirement: within 1 % of U = 1";
  // The discrete parabola is reached much more closely than required (second-order viscous
  // stencil, exact for quadratics away from the walls).
  EXPECT_LE(worst, 1e-3);
}

// The CFL step counts prescribed faces: the channel starts at rest, driven only by its inflow,
// so the first step is cfl dx / (largest inflow face speed), not the scene's dt_max (it was
// 0.5 s, a CFL number of 16). The parabola peaks between face centres: 4 y (1 - y) at
// y = 15.5 / 32.
TEST(Poiseuille, TheFirstCflStepSeesTheInflow) {
  const Registry registry = builtins();
  Simulation<2> sim(loadScene(kScenes + "poiseuille.json"), registry);
  ASSERT_EQ(sim.scene().cfl, 1.0);
  const double y = 15.5 / 32, peak = 4 * y * (1 - y), dx = 4.0 / 128;
  EXPECT_DOUBLE_EQ(sim.nextDt(), dx / peak);
  const auto& diagnostics = sim.step();
  EXPECT_LE(diagnostics.at("fluid_cfl"), 1.0 + 1e-12);
}

TEST(TaylorGreen, ErrorConvergesForBothAdvectionSchemes) {
  const Registry registry = builtins();
  for (const std::string scheme : {"semi_lagrangian", "eno3"}) {
    const double e32 = test::taylorGreen(32, scheme, "coupled", registry).error;
    const double e64 = test::taylorGreen(64, scheme, "coupled", registry).error;
    const double order = std::log2(e32 / e64);
    std::printf("taylor_green %s: error(32) = %.3e, error(64) = %.3e, order %.2f\n", scheme.c_str(), e32, e64, order);
    // Both schemes are first order in time (the projection splitting) and semi-Lagrangian is
    // first order overall at fixed CFL; the error must shrink at least at first order.
    EXPECT_GT(order, 0.8) << scheme;
    EXPECT_LT(e64, 0.05) << scheme;
  }
}

TEST(Cavity, Re100CentreLinesMatchGhiaAt64Cells) {
  // 64 x 64 and dt = 2 dx (CFL about 2) keep the test short; the 128 x 128 scene is measured in the benchmarks.
  const Registry registry = builtins();
  const SceneSpec scene = loadScene(kScenes + "cavity_re100.json",
                                    {{"entities.fluid.mac_grid.cells", "[64, 64]"}, {"time.dt", "0.03125"}});
  Simulation<2> sim(scene, registry);
  runToSteadyState(sim);
  ASSERT_FALSE(sim.finished()) << "no steady state before t = " << scene.endTime;
  const auto [worstU, worstV, uAt, vAt] = test::ghiaDeviation(gridOf(sim), 100);
  std::printf("cavity Re100 64^2: max |u - Ghia| = %.4f, max |v - Ghia| = %.4f at t = %.2f\n", worstU, worstV, sim.time());
  // Issue: <= 0.01 of the lid speed at 128^2 (measured in docs/benchmarks.md). At 64^2 and
  // CFL 2, first-order semi-Lagrangian advection adds numerical diffusion: measured 0.011 (u)
  // and 0.007 (v); 0.015 still fails for a real regression (a wrong viscosity or wall
  // condition moves the profiles by > 0.05).
  EXPECT_LE(worstU, 0.015);
  EXPECT_LE(worstV, 0.015);
}

namespace {
// Re 1000 cavity at 64^2 with Chorin's splitting, to steady state; max centre-line deviations
// from Ghia (u, v).
std::pair<double, double> cavityRe1000At64(const std::string& advection, const std::string& dt) {
  const Registry registry = builtins();
  const SceneSpec scene = loadScene(kScenes + "cavity_re1000.json", {{"entities.fluid.mac_grid.cells", "[64, 64]"},
                                                                      {"time.dt", dt},
                                                                      {"solvers.fluid.projection", "chorin"},
                                                                      {"solvers.fluid.advection", advection}});
  Simulation<2> sim(scene, registry);
  runToSteadyState(sim);
  EXPECT_FALSE(sim.finished()) << advection << ": no steady state before t = " << scene.endTime;
  const auto [worstU, worstV, uAt, vAt] = test::ghiaDeviation(gridOf(sim), 1000);
  std::printf("cavity Re1000 64^2 %s dt %s: max |u - Ghia| = %.4f, max |v - Ghia| = %.4f at t = %.2f\n",
              advection.c_str(), dt.c_str(), worstU, worstV, sim.time());
  return {worstU, worstV};
}
}  // namespace

TEST(Cavity, Re1000MacCormackReachesASteadyStateWithAThirdOfTheSemiLagrangianError) {
  // The 256^2 scene is measured in docs/benchmarks.md (MacCormack, CFL 1). At 64^2: plain
  // semi-Lagrangian at its best step (CFL 4) measured 0.156 / 0.168, limited MacCormack at CFL 1
  // 0.054 / 0.056; both reach max|du|/dt < 1e-6 (ENO3 does not: its stencil switching leaves
  // about 1e-4). A lost correction, or a limiter that stalls the steady state, fails this.
  const auto [slU, slV] = cavityRe1000At64("semi_lagrangian", "0.0625");
  const auto [mcU, mcV] = cavityRe1000At64("maccormack", "0.015625");
  EXPECT_LT(mcU, 0.065);
  EXPECT_LT(mcV, 0.065);
  EXPECT_LT(mcU, 0.5 * slU);
  EXPECT_LT(mcV, 0.5 * slV);
}

TEST(ViscousHigh, CoupledAndChorinReachTheAnalyticChannelProfile) {
  // rho = 100, mu = 10, g = 9.8, h = 1: u(y) = rho g y (h - y) / (2 mu), peak 12.25. With
  // dt nu / dx^2 = 10 both implicit schemes stay stable; the coupled solve must converge at
  // every step and both must land on the profile (the discrete steady state of the
  // second-order viscous stencil with mirrored wall ghosts is within O(dx^2) of it).
  const Registry registry = builtins();
  for (const std::string projection : {"coupled", "chorin"}) {
    Simulation<2> sim(loadScene(kScenes + "viscous_high.json", {{"solvers.fluid.projection", projection}}), registry);
    int worstIterations = 0;
    double worstResidual = 0;
    bool steady = false;
    while (!sim.finished() && !steady) {
      const auto& diag = sim.step();
      worstIterations = std::max(worstIterations, int(diag.at("fluid_solver_iterations")));
      worstResidual = std::max(worstResidual, diag.at("fluid_solver_relative_residual"));
      steady = diag.at("fluid_velocity_change") < sim.scene().stopBelow;
    }
    ASSERT_TRUE(steady) << projection;
    EXPECT_LT(worstIterations, 5000) << projection << ": the solve hit its iteration cap";
    EXPECT_LT(worstResidual, 1e-8) << projection;
    const MacGrid<2>& grid = gridOf(sim);
    const solvers::MacLayout<2> layout(grid.cells, grid.dx, grid.origin, {true, false});
    double worst = 0;
    for (int f = 0; f < layout.faceCount(0); ++f) {
      const auto [axis, index] = layout.faceCoord(f);
      const double y = layout.faceCenter(axis, index).y();
      worst = std::max(worst, std::abs(-grid.u[f] - 100 * 9.8 * y * (1 - y) / 20));
    }
    EXPECT_LE(worst, 0.01 * 12.25) << projection << ": within 1 % of the peak velocity";
    std::printf("viscous_high %s: t = %.1f, max iterations %d, profile error %.2e\n", projection.c_str(), sim.time(),
                worstIterations, worst);
  }
}

TEST(Cavity3D, LidDrivenCubeStaysDivergenceFreeWithNoNetMomentum) {
  // The 3-D path of the fluid step: after each coupled solve the divergence is at solver
  // tolerance, and in a closed box a divergence-free field carries no net momentum along any
  // axis (int u_a dV = boundary flux of x_a u = 0), so all momenta stay at round-off while the
  // lid spins the fluid up (kinetic energy grows).
  const Registry registry = builtins();
  Simulation<3> sim(loadScene(kScenes + "cavity_3d.json",
                              {{"entities.fluid.mac_grid.cells", "[12, 12, 12]"}, {"time.end", "0.4"}}),
                    registry);
  double previousEnergy = 0;
  while (!sim.finished()) {
    const auto& diag = sim.step();
    EXPECT_LT(diag.at("fluid_divergence_max"), 1e-5);  // 1/s; |u| ~ 1, dx = 1/12, tolerance 1e-8
    for (const char* axis : {"linear_momentum_x", "linear_momentum_y", "linear_momentum_z"})
      EXPECT_LT(std::abs(diag.at(axis)), 1e-8) << axis;  // solver tolerance 1e-8 times |u| ~ 1
    EXPECT_GT(diag.at("kinetic_energy"), previousEnergy) << "the lid keeps feeding energy in while spinning up";
    previousEnergy = diag.at("kinetic_energy");
  }
  EXPECT_EQ(sim.stepsDone(), 10);
}

#pragma once
// The decaying Taylor-Green vortex of scenarios/scenes/taylor_green.json run on an n x n grid
// with dt = dx / 2 (landing exactly on t = 1), and its L-infinity velocity error against
// u = sin x cos y e^{-2 nu t}, v = -cos x sin y e^{-2 nu t} (nu = 0.01). Shared by the scenario
// test and the benchmark.
#include <cmath>
#include <cstdio>
#include <string>

#include "components/mac_grid.h"
#include "scenarios/simulation.h"
#include "solvers/mac_layout.h"

namespace monolith::test {

struct TaylorGreenResult {
  double error = 0, seconds = 0;
  long steps = 0;
};

inline TaylorGreenResult taylorGreen(int n, const std::string& advection, const std::string& projection,
                                     const Registry& registry, int threads = 1) {
  const double steps = std::ceil(1.0 / (0.5 * 2 * M_PI / n));
  char dt[32];
  std::snprintf(dt, sizeof dt, "%.17g", 1.0 / steps);
  const SceneSpec scene = loadScene(std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes/taylor_green.json",
                                    {{"entities.fluid.mac_grid.cells", "[" + std::to_string(n) + "," + std::to_string(n) + "]"},
                                     {"time.dt", dt},
                                     {"solvers.fluid.advection", advection},
                                     {"solvers.fluid.projection", projection}});
  Simulation<2> sim(scene, registry, threads);
  const auto t0 = std::chrono::steady_clock::now();
  while (!sim.finished()) sim.step();
  TaylorGreenResult r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.steps = sim.stepsDone();
  const MacGrid<2>& grid = sim.world().pool<MacGrid<2>>().components()[0];
  const solvers::MacLayout<2> layout(grid.cells, grid.dx, grid.origin, {true, true});
  const double decay = std::exp(-2 * 0.01 * sim.time());
  for (int f = 0; f < layout.totalFaces(); ++f) {
    const auto [axis, index] = layout.faceCoord(f);
    const auto x = layout.faceCenter(axis, index);
    const double exact = axis == 0 ? std::sin(x.x()) * std::cos(x.y()) * decay : -std::cos(x.x()) * std::sin(x.y()) * decay;
    r.error = std::max(r.error, std::abs(grid.u[f] - exact));
  }
  return r;
}

}  // namespace monolith::test

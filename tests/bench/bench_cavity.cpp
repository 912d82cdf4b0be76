// Lid-driven cavity to steady state (Ghia, Ghia & Shin 1982): wall time against the error of
// the centre-line profiles. Runs scenarios/scenes/cavity_re100.json (and cavity_re1000.json with
// the argument "1000") through the real pipeline; steady state = max|du|/dt < 1e-6 (the scene's
// stop criterion).
//
// usage: bench_cavity [100|1000] [cells] [threads] [coupled|chorin] [CFL: dt = CFL / cells, default 1]
//                    [semi_lagrangian|maccormack|eno3]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "components/mac_grid.h"
#include "scenarios/fluid_fields.h"
#include "scenarios/simulation.h"
#include "support/ghia.h"

using namespace monolith;

int main(int argc, char** argv) {
  const int re = argc > 1 ? std::atoi(argv[1]) : 100;
  const std::string file = std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes/cavity_re" + std::to_string(re) + ".json";
  std::vector<Override> overrides;
  if (argc > 2) {
    const int n = std::atoi(argv[2]);
    char dt[32];
    const double cfl = argc > 5 ? std::atof(argv[5]) : 1.0;  // CFL about 1, as in the scenes
    std::snprintf(dt, sizeof dt, "%.17g", cfl / n);
    overrides = {{"entities.fluid.mac_grid.cells", "[" + std::to_string(n) + "," + std::to_string(n) + "]"}, {"time.dt", dt}};
  }
  const int threads = argc > 3 ? std::atoi(argv[3]) : 2;
  const std::string projection = argc > 4 ? argv[4] : "coupled";
  overrides.push_back({"solvers.fluid.projection", projection});
  if (argc > 6) overrides.push_back({"solvers.fluid.advection", argv[6]});
  Registry registry;
  registerBuiltins(registry);
  const SceneSpec scene = loadScene(file, overrides);
  Simulation<2> sim(scene, registry, threads);
  const auto t0 = std::chrono::steady_clock::now();
  double iterations = 0;
  long steps = 0;
  bool steady = false;
  while (!sim.finished() && !steady) {
    const auto& diag = sim.step();
    iterations += diag.at("fluid_solver_iterations");
    ++steps;
    steady = diag.at(scene.stopDiagnostic) < scene.stopBelow;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const MacGrid<2>& grid = sim.world().pool<MacGrid<2>>().components()[0];
  const auto [worstU, worstV, worstUAt, worstVAt] = test::ghiaDeviation(grid, re);
  std::printf("largest deviations: u at y = %.4f, v at x = %.4f\n", worstUAt, worstVAt);
  std::printf("| Re | cells | projection | threads | steady | t | steps | CG iterations/step | wall s | ms/step | max abs(u - Ghia) | max abs(v - Ghia) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::printf("| %d | %d^2 | %s | %d | %s | %.2f | %ld | %.1f | %.1f | %.2f | %.4f | %.4f |\n", re, grid.cells[0], projection.c_str(), threads,
              steady ? "yes" : "NO", sim.time(), steps, iterations / steps, seconds,
              1e3 * seconds / steps, worstU, worstV);
  return 0;
}

// Laminar flow past a cylinder, thesis Sec. 5.11.3: the velocity at (3, 2.25) at t = 0.5 s from
// the coupled pressure-viscosity solve at 40^2 ... 320^2 against Chorin's splitting at the finest
// resolution (the thesis's "exact" solution is Chorin at 640^2; it measures orders 0.89 for u_1
// and 1.07 for u_2). Also prints Chorin at every resolution, so both schemes' convergence shows.
// dt = dx / 2 at every resolution (scenarios/scenes/cylinder_laminar.json).
//
// usage: bench_cylinder_laminar [finest cells, default 640] [threads, default 2]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "components/mac_grid.h"
#include "scenarios/fluid_fields.h"
#include "scenarios/simulation.h"

using namespace monolith;

namespace {
struct Sample {
  Eigen::Vector2d u = Eigen::Vector2d::Zero();
  double seconds = 0;
  long steps = 0;
};

Sample run(const Registry& registry, const std::string& projection, int n, int threads) {
  const std::string file = std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes/cylinder_laminar.json";
  char dt[32];
  std::snprintf(dt, sizeof dt, "%.17g", 0.5 * 4.0 / n);
  const std::vector<Override> overrides = {
      {"entities.fluid.mac_grid.cells", "[" + std::to_string(n) + "," + std::to_string(n) + "]"},
      {"solvers.fluid.projection", projection},
      {"time.dt", dt}};
  const SceneSpec scene = loadScene(file, overrides);
  Simulation<2> sim(scene, registry, threads);
  const auto t0 = std::chrono::steady_clock::now();
  while (!sim.finished()) sim.step();
  Sample s;
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  s.steps = sim.stepsDone();
  s.u = sampleVelocity(sim.world().pool<MacGrid<2>>().components()[0], Eigen::Vector2d(3, 2.25));
  return s;
}
}  // namespace

int main(int argc, char** argv) {
  const int finest = argc > 1 ? std::atoi(argv[1]) : 640;
  const int threads = argc > 2 ? std::atoi(argv[2]) : 2;
  Registry registry;
  registerBuiltins(registry);
  const Sample reference = run(registry, "chorin", finest, threads);
  std::printf("reference: Chorin at %d^2: u = (%.6f, %.6f), %ld steps, %.1f s\n\n", finest, reference.u.x(),
              reference.u.y(), reference.steps, reference.seconds);
  std::printf("| projection | cells | steps | wall s | u_1 | u_2 | abs err u_1 | order | abs err u_2 | order |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string projection : {"coupled", "chorin"}) {
    Eigen::Vector2d previous = Eigen::Vector2d::Zero();
    for (int n = 40; n < finest; n *= 2) {
      const Sample s = run(registry, projection, n, threads);
      const Eigen::Vector2d error = (s.u - reference.u).cwiseAbs();
      char o1[16] = "", o2[16] = "";
      if (n > 40) {
        std::snprintf(o1, sizeof o1, "%.2f", std::log2(previous.x() / error.x()));
        std::snprintf(o2, sizeof o2, "%.2f", std::log2(previous.y() / error.y()));
      }
      std::printf("| %s | %d^2 | %ld | %.2f | %.6f | %.6f | %.2e | %s | %.2e | %s |\n", projection.c_str(), n, s.steps,
                  s.seconds, s.u.x(), s.u.y(), error.x(), o1, error.y(), o2);
      std::fflush(stdout);
      previous = error;
    }
  }
  return 0;
}

// Karman vortex shedding behind a cylinder, thesis Sec. 5.11.4 (REFERENCES.md): Strouhal number
// St = f D / U of the lift force for the coupled pressure-viscosity solve and for Chorin's
// splitting, with wall time. The thesis measured St = 0.160 (its method) and 0.166 (Chorin) at
// 400 x 160; the literature it cites gives 0.164-0.173. Runs scenarios/scenes/vortex_shedding.json
// through the real pipeline; the period is taken over the second half of the run.
//
// usage: bench_vortex_shedding [coupled|chorin|both] [cells across, default 160] [threads, 1]
//                              [end time, default 150]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "scenarios/simulation.h"
#include "support/oscillation.h"

using namespace monolith;

namespace {
constexpr double kD = 1, kU = 1, kRho = 1;  // the scene's diameter, inflow speed, density
constexpr double kLiteratureLow = 0.164, kLiteratureHigh = 0.173;

void run(const Registry& registry, const std::string& projection, int ny, int threads, const std::string& end) {
  const std::string file = std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes/vortex_shedding.json";
  const int nx = ny * 5 / 2;  // square cells on [-2.5, 15] x [-3.5, 3.5]
  const std::vector<Override> overrides = {
      {"entities.fluid.mac_grid.cells", "[" + std::to_string(nx) + "," + std::to_string(ny) + "]"},
      {"solvers.fluid.projection", projection},
      {"time.end", end}};
  const SceneSpec scene = loadScene(file, overrides);
  Simulation<2> sim(scene, registry, threads);
  std::vector<double> t, lift, drag;
  double iterations = 0;
  const auto t0 = std::chrono::steady_clock::now();
  while (!sim.finished()) {
    const auto& diag = sim.step();
    t.push_back(sim.time());
    drag.push_back(2 * diag.at("obstacle_cylinder_force_x") / (kRho * kU * kU * kD));
    lift.push_back(2 * diag.at("obstacle_cylinder_force_y") / (kRho * kU * kU * kD));
    iterations += diag.at("fluid_solver_iterations") + diag.at("fluid_viscosity_iterations");
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double from = 0.5 * sim.time();
  const test::Oscillation cl = test::analyseOscillation(t, lift, from);
  const test::Oscillation cd = test::analyseOscillation(t, drag, from);
  const double st = cl.frequency() * kD / kU;
  const double thesis = projection == "chorin" ? 0.166 : 0.160;
  const double outside = st < kLiteratureLow ? st - kLiteratureLow : st > kLiteratureHigh ? st - kLiteratureHigh : 0.0;
  std::printf("| %s | %dx%d | %d | %.0f | %ld | %.1f | %.1f | %.1f | %d | %.4f | %+.1f%% | %+.4f | %.3f | %.3f |\n",
              projection.c_str(), nx, ny, threads, sim.time(), sim.stepsDone(), seconds,
              1000 * seconds / sim.stepsDone(), iterations / sim.stepsDone(), cl.crossings - 1, st,
              100 * (st - thesis) / thesis, outside, cd.mean, 0.5 * (cl.max - cl.min));
  std::fflush(stdout);
}
}  // namespace

int main(int argc, char** argv) {
  const std::string which = argc > 1 ? argv[1] : "both";
  const int ny = argc > 2 ? std::atoi(argv[2]) : 160;
  const int threads = argc > 3 ? std::atoi(argv[3]) : 1;
  const std::string end = argc > 4 ? argv[4] : "150";
  Registry registry;
  registerBuiltins(registry);
  std::printf("| projection | cells | threads | t end | steps | wall s | ms/step | CG iterations/step | periods | St | St vs thesis | St outside 0.164-0.173 | mean c_D | c_L amplitude |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  if (which == "coupled" || which == "both") run(registry, "coupled", ny, threads, end);
  if (which == "chorin" || which == "both") run(registry, "chorin", ny, threads, end);
  return 0;
}

// Schaefer-Turek DFG 2D-1 (steady Re 20 flow past a cylinder, REFERENCES.md): drag and lift
// coefficients and the pressure difference across the cylinder against the reference values,
// at several resolutions, with the scene's settings (cut faces, wall at the surface, WENO5; the
// thesis's staircase: add solvers.fluid.obstacle_cells=staircase solvers.fluid.obstacle_wall=face
// solvers.fluid.advection=semi_lagrangian). Runs scenarios/scenes/dfg_2d1.json through the real
// pipeline to steady state (max|du|/dt < 1e-6, the scene's stop criterion).
//
// With the first argument "2d2" it runs the periodic benchmark 2D-2 (dfg_2d2.json, Re 100)
// instead: maximum c_D and c_L and the Strouhal number St = D f / Ubar of the lift, measured over
// the second half of the run (the shedding has settled by then).
//
// usage: bench_dfg [2d2] [max cells across the channel: 41|82|164] [threads] [end time, default the scene's]
//                  [first cells across, default 41] [key=value scene overrides, e.g.
//                  solvers.fluid.obstacle_cells=cut solvers.fluid.obstacle_wall=surface; scene=FILE runs
//                  another scene of scenarios/scenes/, e.g. scene=dfg_2d1_level_set.json]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "components/mac_grid.h"
#include "scenarios/fluid_fields.h"
#include "scenarios/simulation.h"
#include "support/oscillation.h"

using namespace monolith;

namespace {
constexpr double kCD = 5.57953523384, kCL = 0.010618948146, kDP = 0.11752016697;  // reference
constexpr double kUbar = 0.2, kD = 0.1, kRho = 1;

// Pressure at x, bilinear from the cell centres around it but over fluid cells only (weights
// renormalized): solid cells carry p = 0, and both probe points (0.15, 0.2) and (0.25, 0.2) lie
// on the disk's boundary, so samplePressure would mix those zeros in (it halves dP at dx = 0.01).
double fluidPressure(const MacGrid<2>& grid, const Eigen::Vector2d& x) {
  const Eigen::Vector2d s = (x - grid.origin) / grid.dx - Eigen::Vector2d::Constant(0.5);
  const int i0 = int(std::floor(s.x())), j0 = int(std::floor(s.y()));
  double sum = 0, weights = 0;
  for (int di = 0; di <= 1; ++di)
    for (int dj = 0; dj <= 1; ++dj) {
      const int i = i0 + di, j = j0 + dj;
      if (i < 0 || j < 0 || i >= grid.cells[0] || j >= grid.cells[1]) continue;
      const int c = i + grid.cells[0] * j;
      if (grid.solid[c]) continue;
      const double w = (di ? s.x() - i0 : 1 - (s.x() - i0)) * (dj ? s.y() - j0 : 1 - (s.y() - j0));
      sum += w * grid.p[c];
      weights += w;
    }
  return weights > 0 ? sum / weights : 0.0;
}

struct Row {
  int ny = 0;
  long steps = 0;
  double seconds = 0, t = 0, cD = 0, cL = 0, dP = 0, dPraw = 0, change = 0;
  bool steady = false;
};

std::vector<Override> extraOverrides;  // key=value arguments
std::string sceneName;                 // scene=FILE (in scenarios/scenes/): another scene of the benchmark

Row run(const Registry& registry, int ny, int threads, const std::string& end) {
  const std::string file =
      std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes/" + (sceneName.empty() ? "dfg_2d1.json" : sceneName);
  const int nx = ny * 220 / 41;  // square cells: 2.2 / nx = 0.41 / ny
  std::vector<Override> overrides = {
      {"entities.fluid.mac_grid.cells", "[" + std::to_string(nx) + "," + std::to_string(ny) + "]"}};
  char dt[32];
  std::snprintf(dt, sizeof dt, "%.17g", 0.025 * 41 / ny);  // the scene's CFL about 0.95 at every resolution
  overrides.push_back({"time.dt", dt});
  if (!end.empty()) overrides.push_back({"time.end", end});
  overrides.insert(overrides.end(), extraOverrides.begin(), extraOverrides.end());
  const SceneSpec scene = loadScene(file, overrides);
  Simulation<2> sim(scene, registry, threads);
  Row r;
  r.ny = ny;
  const auto t0 = std::chrono::steady_clock::now();
  double fx = 0, fy = 0;
  while (!sim.finished()) {
    const auto& diag = sim.step();
    fx = diag.at("obstacle_cylinder_force_x");
    fy = diag.at("obstacle_cylinder_force_y");
    r.change = diag.at(scene.stopDiagnostic);
    if (diag.at(scene.stopDiagnostic) < scene.stopBelow) {
      r.steady = true;
      break;
    }
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const MacGrid<2>& grid = sim.world().pool<MacGrid<2>>().components()[0];
  r.steps = sim.stepsDone();
  r.t = sim.time();
  r.cD = 2 * fx / (kRho * kUbar * kUbar * kD);
  r.cL = 2 * fy / (kRho * kUbar * kUbar * kD);
  r.dP = fluidPressure(grid, Eigen::Vector2d(0.15, 0.2)) - fluidPressure(grid, Eigen::Vector2d(0.25, 0.2));
  r.dPraw = samplePressure(grid, Eigen::Vector2d(0.15, 0.2)) - samplePressure(grid, Eigen::Vector2d(0.25, 0.2));
  return r;
}
// DFG 2D-2 (Re 100, periodic): references c_D,max = 3.23, c_L,max = 1.00, St in [0.295, 0.305].
constexpr double kCDmax = 3.23, kCLmax = 1.00, kSt = 0.300, kUbar2 = 1.0;

void runPeriodic(const Registry& registry, int ny, int threads, const std::string& end) {
  const std::string file =
      std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes/" + (sceneName.empty() ? "dfg_2d2.json" : sceneName);
  const int nx = ny * 220 / 41;
  std::vector<Override> overrides = {
      {"entities.fluid.mac_grid.cells", "[" + std::to_string(nx) + "," + std::to_string(ny) + "]"}};
  char dt[32];
  std::snprintf(dt, sizeof dt, "%.17g", 0.004 * 41 / ny);  // CFL about 0.9 at every resolution
  overrides.push_back({"time.dt", dt});
  if (!end.empty()) overrides.push_back({"time.end", end});
  overrides.insert(overrides.end(), extraOverrides.begin(), extraOverrides.end());
  const SceneSpec scene = loadScene(file, overrides);
  Simulation<2> sim(scene, registry, threads);
  std::vector<double> t, cD, cL;
  const double scale = 2 / (kRho * kUbar2 * kUbar2 * kD);
  const auto t0 = std::chrono::steady_clock::now();
  while (!sim.finished()) {
    const auto& diag = sim.step();
    t.push_back(sim.time());
    cD.push_back(scale * diag.at("obstacle_cylinder_force_x"));
    cL.push_back(scale * diag.at("obstacle_cylinder_force_y"));
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const test::Oscillation lift = test::analyseOscillation(t, cL, 0.5 * sim.time());
  const test::Oscillation drag = test::analyseOscillation(t, cD, 0.5 * sim.time());
  const double st = lift.frequency() * kD / kUbar2;
  std::printf("| %dx%d | %.2f | %ld | %.1f | %d | %.4f | %+.1f%% | %.4f | %+.1f%% | %.4f | %+.1f%% |\n", nx, ny, sim.time(),
              sim.stepsDone(), seconds, lift.crossings - 1, drag.max, 100 * (drag.max - kCDmax) / kCDmax, lift.max,
              100 * (lift.max - kCLmax) / kCLmax, st, 100 * (st - kSt) / kSt);
  std::fflush(stdout);
}
}  // namespace

int main(int argc, char** argv) {
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto eq = arg.find('=');
    if (eq == std::string::npos) argv[kept++] = argv[i];
    else if (arg.substr(0, eq) == "scene") sceneName = arg.substr(eq + 1);
    else extraOverrides.push_back({arg.substr(0, eq), arg.substr(eq + 1)});
  }
  argc = kept;
  const bool periodic = argc > 1 && std::string(argv[1]) == "2d2";
  if (periodic) --argc, ++argv;
  const int maxNy = argc > 1 ? std::atoi(argv[1]) : 164;
  const int threads = argc > 2 ? std::atoi(argv[2]) : 2;
  const std::string end = argc > 3 ? argv[3] : "";
  const int firstNy = argc > 4 ? std::atoi(argv[4]) : 41;
  Registry registry;
  registerBuiltins(registry);
  if (periodic) {
    std::printf("| cells | t end | steps | wall s | periods | c_D max | err | c_L max | err | St | err |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (int ny = firstNy; ny <= maxNy; ny *= 2) runPeriodic(registry, ny, threads, end);
    return 0;
  }
  std::printf("| cells | steady | t | final max du/dt | steps | wall s | c_D | err c_D | c_L | err c_L | dP | err dP | dP (samplePressure) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int ny = firstNy; ny <= maxNy; ny *= 2) {
    const Row r = run(registry, ny, threads, end);
    std::printf("| %dx%d | %s | %.2f | %.1e | %ld | %.1f | %.4f | %+.1f%% | %.5f | %+.0f%% | %.5f | %+.1f%% | %.5f |\n",
                ny * 220 / 41, ny, r.steady ? "yes" : "NO", r.t, r.change, r.steps, r.seconds, r.cD,
                100 * (r.cD - kCD) / kCD, r.cL, 100 * (r.cL - kCL) / kCL, r.dP, 100 * (r.dP - kDP) / kDP, r.dPraw);
    std::fflush(stdout);
    if (r.seconds > 240) break;  // the next resolution would take > 4x as long
  }
  return 0;
}

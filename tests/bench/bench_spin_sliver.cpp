// Speed against error for the frame-rate orientation update (thesis Sec. 2.2, 4.4.1, App. A).
// Runs scenarios/scenes/spin_sliver.json through the real pipeline (world + scheduler, 1 thread)
// with dt = 1/30 ... 1/240 (and finer, to show the asymptotic orders), the first/second/third
// order rules, the energy fix off and on. Prints a markdown table: orientation error at T
// against a converged reference (RK4 on Euler's equations, 40000 substeps), the observed order
// between successive step sizes, the worst relative kinetic-energy change of a step, and the
// wall time per step (best of several repeats).
//
// Two horizons: T = 0.2 s (6 steps at 1/30: the asymptotic regime, where the observed orders
// 1/2/3 show at frame-rate step sizes) and T = 1 s (through the unstable intermediate-axis
// motion, where the first-order rule without the fix is O(1) wrong until dt ~ 1/1000).
//
// usage: bench_spin_sliver [repeats, default 5] [T seconds ...]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "components/rigid_body.h"
#include "scenarios/simulation.h"
#include "solvers/torque_free_reference.h"

using namespace monolith;

namespace {

struct Result {
  double error = 0, worstEnergyChange = 0, microsecondsPerStep = 0;
};

Result runCase(int order, bool fix, int stepsPerSecond, double T, int repeats, const Eigen::Quaterniond& reference) {
  Registry registry;
  registerBuiltins(registry);
  const long steps = std::lround(T * stepsPerSecond);
  char dt[32];
  std::snprintf(dt, sizeof dt, "%.17g", 1.0 / stepsPerSecond);  // full precision: T = steps * dt exactly
  const std::vector<Override> overrides = {{"time.dt", dt},
                                           {"time.steps", std::to_string(steps)},
                                           {"solvers.rigid_rotation.order", std::to_string(order)},
                                           {"solvers.rigid_rotation.energy_fix", fix ? "true" : "false"}};
  const SceneSpec scene = loadScene(std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes/spin_sliver.json", overrides);
  Result r;
  r.microsecondsPerStep = 1e300;
  for (int rep = 0; rep < repeats; ++rep) {
    Simulation<3> sim(scene, registry, 1);
    auto& body = sim.world().pool<RigidBody<3>>().components()[0];
    double worst = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (long n = 0; n < steps; ++n) {
      const double before = body.rotationalKineticEnergy();
      sim.step();
      worst = std::max(worst, std::abs(body.rotationalKineticEnergy() - before) / before);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.microsecondsPerStep = std::min(r.microsecondsPerStep, 1e6 * seconds / steps);
    r.error = solvers::rotationAngleBetween(body.orientation, reference);
    r.worstEnergyChange = worst;
  }
  return r;
}

}  // namespace

void table(double T, int repeats);

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 5;
  std::vector<double> horizons;
  for (int i = 2; i < argc; ++i) horizons.push_back(std::atof(argv[i]));
  if (horizons.empty()) horizons = {0.2, 1.0};
  for (double T : horizons) table(T, repeats);
  return 0;
}

void table(double T, int repeats) {
  // The scene's body: box half-extents (0.05, 0.5, 1.5), mass 1, w0 = (0.1, 10, 0.1), R0 = I.
  Registry registry;
  registerBuiltins(registry);
  const SceneSpec scene = loadScene(std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes/spin_sliver.json");
  Simulation<3> initial(scene, registry, 1);
  const auto& body0 = initial.world().pool<RigidBody<3>>().components()[0];
  const solvers::BodyInertia inertia = solvers::BodyInertia::fromMatrix(body0.inertiaBody);
  const Eigen::Quaterniond reference =
      solvers::torqueFreeReferenceOrientation(inertia, body0.orientation, body0.L, T, 40000);

  const std::vector<int> rates = {30, 60, 120, 240, 480, 960};
  std::printf("spin_sliver: orientation error at T = %g s vs converged reference (rad); order = log2(e(dt)/e(dt/2))\n\n", T);
  std::printf("| rule | energy fix | steps/s | error (rad) | observed order | max rel. dKE per step | us/step |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (int order = 1; order <= 3; ++order)
    for (bool fix : {false, true}) {
      double previous = 0;
      for (int rate : rates) {
        const Result r = runCase(order, fix, rate, T, repeats, reference);
        char orderText[32] = "";
        if (previous > 0) std::snprintf(orderText, sizeof orderText, "%.2f", std::log2(previous / r.error));
        std::printf("| %d | %s | %d | %.3e | %s | %.1e | %.2f |\n", order, fix ? "on" : "off", rate, r.error, orderText,
                    r.worstEnergyChange, r.microsecondsPerStep);
        previous = r.error;
      }
    }
  std::printf("\n");
}

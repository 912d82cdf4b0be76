// A long chain of capsule links on spherical joints, pinned at one end and released
// horizontally under gravity (chain_hanging, scaled up): wall time per step against the joint
// error, for pairwise (Gauss-Seidel) and global (App. C, CG) post- and pre-stabilization, at a
// few iteration budgets. Error columns: the largest joint_error_max (m) and
// joint_velocity_error_max (m/s) over the run, and the energy at the end against the start (J).
//
// usage: bench_articulation [links, default 1000] [steps, default 60]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "components/rigid_body.h"
#include "scenarios/simulation.h"

using namespace monolith;

namespace {

std::string sceneText(int links, long steps, const std::string& method, int postIterations, int preIterations) {
  const double length = 0.1, radius = 0.01;
  std::string entities;
  char buf[600];
  for (int i = 0; i < links; ++i) {
    std::snprintf(buf, sizeof buf,
                  R"(%s{"name": "l%d", "shape": {"type": "capsule", "radius": %g, "half_height": %g},
                      "rigid_body": {"mass": 0.1, "position": [%.17g, 0, 0], "orientation": [0.7071067811865476, 0, 0.7071067811865476, 0]},
                      "joint": {"type": "spherical", "parent": "%s", "anchor": [%.17g, 0, 0]}})",
                  i ? "," : "", i, radius, 0.5 * length - radius, (i + 0.5) * length,
                  i == 0 ? "world" : ("l" + std::to_string(i - 1)).c_str(), i * length);
    entities += buf;
  }
  std::snprintf(buf, sizeof buf,
                R"(, {"name": "solver", "articulation": {"post_stabilization": "%s", "pre_stabilization": "%s",
                     "post_iterations": %d, "pre_iterations": %d, "post_tolerance": 1e-10, "pre_tolerance": 1e-10}})",
                method.c_str(), method.c_str(), postIterations, preIterations);
  entities += buf;
  return R"({"dimension": 3, "time": {"dt": 0.004166666666666667, "steps": )" + std::to_string(steps) +
         R"(}, "gravity": [0, -9.81, 0], "entities": [)" + entities + "]}";
}

double energy(Simulation<3>& sim) {
  double e = 0;
  for (const auto& b : sim.world().pool<RigidBody<3>>().components())
    e += b.translationalKineticEnergy() + b.rotationalKineticEnergy() + 9.81 * b.mass * b.x.y();
  return e;
}

}  // namespace

int main(int argc, char** argv) {
  const int links = argc > 1 ? std::atoi(argv[1]) : 1000;
  const long steps = argc > 2 ? std::atol(argv[2]) : 60;
  Registry registry;
  registerBuiltins(registry);
  std::printf("chain of %d links, %ld steps at dt = 1/240, 1 thread\n\n", links, steps);
  std::printf("| method | post iterations | pre iterations | us/step | max joint_error_max (m) | max joint_velocity_error_max (m/s) | energy end - start (J) |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  struct Case {
    const char* method;
    int post, pre;
  };
  // Global: post_iterations is CG iterations per joint (budget post x joints), pre_iterations
  // outer Newton iterations. Pairwise: sweeps.
  for (const Case c : {Case{"pairwise", 50, 20}, Case{"pairwise", 500, 200}, Case{"global", 1, 3}, Case{"global", 5, 5},
                       Case{"global", 50, 20}}) {
    Simulation<3> sim(parseScene(sceneText(links, steps, c.method, c.post, c.pre), "chain.json"), registry, 1);
    const double start = energy(sim);
    double position = 0, velocity = 0;
    const auto t0 = std::chrono::steady_clock::now();
    while (!sim.finished()) {
      const auto& d = sim.step();
      position = std::max(position, d.at("joint_error_max"));
      velocity = std::max(velocity, d.at("joint_velocity_error_max"));
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("| %s | %d | %d | %.0f | %.3g | %.3g | %.4g |\n", c.method, c.post, c.pre, 1e6 * seconds / steps, position,
                velocity, energy(sim) - start);
    std::fflush(stdout);
  }
  return 0;
}

// Throughput of the rigid free-flight step (all stages, energy fix on) against the number of
// bodies, on 1 and 2 threads. Error column: worst relative rotational-energy change of any body
// over the run (must stay at round-off) and whether the 1- and 2-thread states are bitwise equal.
//
// usage: bench_free_flight_throughput [steps, default 200] [repeats, default 3]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "components/rigid_body.h"
#include "scenarios/checkpoint.h"
#include "scenarios/simulation.h"

using namespace monolith;

namespace {

std::string sceneText(int bodies, long steps) {
  std::string entities;
  for (int i = 0; i < bodies; ++i) {
    char buf[400];
    std::snprintf(buf, sizeof buf,
                  R"(%s{"shape": {"type": "box", "half_extents": [%.3f, %.3f, %.3f]},
                      "rigid_body": {"mass": 1, "position": [%d, %d, %d], "velocity": [0, 5, 0],
                                     "angular_velocity": [%.2f, %.2f, 0.1]}})",
                  i ? "," : "", 0.05 + 0.01 * (i % 5), 0.5, 1.5 - 0.1 * (i % 3), i % 100, (i / 100) % 100, i / 10000,
                  0.1 * (i % 7), 10.0 - i % 4);
    entities += buf;
  }
  return R"({"dimension": 3, "time": {"dt": 0.03333333333333333, "steps": )" + std::to_string(steps) +
         R"(}, "gravity": [0, -9.81, 0], "entities": [)" + entities + "]}";
}

}  // namespace

int main(int argc, char** argv) {
  const long steps = argc > 1 ? std::atol(argv[1]) : 200;
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 3;
  Registry registry;
  registerBuiltins(registry);
  std::printf("| bodies | threads | us/step | us/body-step | speed-up | max rel. dKE (run) | 1T == 2T state |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (int bodies : {100, 1000, 10000}) {
    const SceneSpec scene = parseScene(sceneText(bodies, steps), "throughput.json");
    double oneThread = 0;
    std::uint64_t hashes[3] = {0, 0, 0};
    for (int threads : {1, 2}) {
      double best = 1e300, worstEnergy = 0;
      for (int rep = 0; rep < repeats; ++rep) {
        Simulation<3> sim(scene, registry, threads);
        auto& pool = sim.world().pool<RigidBody<3>>().components();
        std::vector<double> e0;
        for (const auto& b : pool) e0.push_back(b.rotationalKineticEnergy());
        const auto t0 = std::chrono::steady_clock::now();
        for (long n = 0; n < steps; ++n) sim.step();
        best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        for (std::size_t i = 0; i < pool.size(); ++i)
          worstEnergy = std::max(worstEnergy, std::abs(pool[i].rotationalKineticEnergy() - e0[i]) / e0[i]);
        hashes[threads] = stateHash(sim.world());
      }
      const double us = 1e6 * best / steps;
      if (threads == 1) oneThread = us;
      std::printf("| %d | %d | %.1f | %.3f | %.2f | %.1e | %s |\n", bodies, threads, us, us / bodies, oneThread / us,
                  worstEnergy, threads == 2 ? (hashes[1] == hashes[2] ? "yes" : "NO") : "");
    }
  }
  return 0;
}

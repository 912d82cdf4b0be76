// The rigid/face contact system alone (systems/rigid_surface_contact.h) on one and two threads:
// a scene (default small_bodies_on_cloth: its rigid ball and cube in the sheet) is stepped to a
// time (default 0.3 s), then each stage's system is run `repeat` times on a copy of that state
// per thread count; prints the wall time per call and checks that both thread counts leave the
// same velocities (bitwise). Usage: bench_rigid_surface_contact [REPEAT [SCENE [TIME]]].
#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "components/deformable.h"
#include "ecs/registry.h"
#include "scenarios/checkpoint.h"
#include "scenarios/simulation.h"
#include "systems/rigid_surface_contact.h"

using namespace monolith;

int main(int argc, char** argv) {
  const int repeat = argc > 1 ? std::atoi(argv[1]) : 200;
  Registry registry;
  registerBuiltins(registry);
  const std::string scene =
      argc > 2 ? argv[2] : std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes/small_bodies_on_cloth.json";
  const std::string until = argc > 3 ? argv[3] : "0.3";
  Simulation<3> sim(loadScene(scene, {{"time.end", until}}), registry, 1);
  while (!sim.finished()) sim.step();
  const std::uint64_t start = stateHash(sim.world());
  std::uint64_t after[2] = {0, 0};
  for (int threads : {1, 2}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    Simulation<3> copy(loadScene(scene, {{"time.end", until}}), registry, threads);
    while (!copy.finished()) copy.step();
    if (stateHash(copy.world()) != start) std::printf("warning: the copy's state differs\n");
    for (Stage stage : {Stage::Collisions, Stage::Contact, Stage::AdvancePositions, Stage::AdvanceVelocity}) {
      RigidSurfaceContact<3> system(stage);
      StepContext ctx;
      ctx.dt = sim.lastDt();
      system.run(copy.world(), ctx);  // warm: the BVH built, the buffers sized
      const auto t0 = std::chrono::steady_clock::now();
      for (int k = 0; k < repeat; ++k) system.run(copy.world(), ctx);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::printf("%d thread(s) %-32s %8.1f us per call\n", threads, system.name().c_str(), 1e6 * seconds / repeat);
    }
    after[threads - 1] = stateHash(copy.world());
  }
  std::printf("state after the calls: 1 and 2 threads %s\n", after[0] == after[1] ? "bitwise equal" : "DIFFER");
  return after[0] == after[1] ? 0 : 1;
}

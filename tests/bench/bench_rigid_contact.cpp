// Rigid contact benchmarks (issue 3): speed against error.
//  * pyramid_20 (210 boxes) and pyramid_10 at dt = 1/30 and 1/60 for 10 s, on 1 and 2 threads:
//    us/step, max drift of any box from its start, final kinetic energy (the issue asks: stand at
//    1/30 s, drift < 0.05), and whether the 1- and 2-thread states are bitwise equal.
//  * pour_spheres_N, N = 250, 1000, 4000 (generated with scenarios/scenes/generate_contact_scenes.py):
//    us/step on 1 and 2 threads, deepest penetration relative to the sphere size, and whether the
//    1- and 2-thread states are bitwise equal.
//  * mixed_pile (boxes, spheres, capsules, cylinders, octahedra): us/step on 1 and 2 threads,
//    deepest overlap, final kinetic energy, 1T == 2T.
//
// usage: bench_rigid_contact [pyramid|pour|mixed|all, default all] [seconds] [pyramid scene, e.g. pyramid_20]
//                            [key=value scene overrides for the pyramids, e.g. solvers.contact.contact_iterations=4]
//   seconds: simulated time per run; pour default 1.0, pyramids default the scenes' 10 s (a
//   shorter run is for quick comparisons while profiling; report the 10 s numbers).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

#include "components/rigid_body.h"
#include "scenarios/simulation.h"

using namespace monolith;

namespace {

const std::string kScenes = std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes/";

void pyramids(const Registry& registry, double seconds, const std::string& only, const std::vector<Override>& extra) {
  std::printf("| scene | boxes | dt | steps | threads | us/step | speed-up | max drift | final KE | max penetration / size | 1T == 2T |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const char* name : {"pyramid_10", "pyramid_20"}) {
    if (!only.empty() && only != name) continue;
    for (double dt : {1.0 / 30, 1.0 / 60}) {
      char dtText[64];
      std::snprintf(dtText, sizeof dtText, "%.17g", dt);
      char end[64];
      std::snprintf(end, sizeof end, "%.17g", seconds);
      std::vector<Override> overrides = extra;
      overrides.push_back({"time.dt", dtText});
      if (seconds > 0) overrides.push_back({"time.end", end});
      const SceneSpec scene = loadScene(kScenes + name + ".json", overrides);
      double oneThread = 0;
      std::vector<RigidBody<3>> reference;
      for (int threads : {1, 2}) {
        Simulation<3> sim(scene, registry, threads);
        auto& bodies = sim.world().pool<RigidBody<3>>().components();
        std::vector<Eigen::Vector3d> start;
        for (const auto& b : bodies) start.push_back(b.x);
        double penetration = 0;
        const auto t0 = std::chrono::steady_clock::now();
        while (!sim.finished()) penetration = std::max(penetration, sim.step().at("max_penetration_ratio"));
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        double drift = 0, ke = 0;
        int dynamic = 0;
        bool equal = true;
        for (std::size_t i = 0; i < bodies.size(); ++i) {
          if (threads == 2)
            equal = equal && std::memcmp(bodies[i].x.data(), reference[i].x.data(), 3 * sizeof(double)) == 0 &&
                    std::memcmp(bodies[i].v.data(), reference[i].v.data(), 3 * sizeof(double)) == 0;
          if (bodies[i].isStatic) continue;
          ++dynamic;
          drift = std::max(drift, (bodies[i].x - start[i]).norm());
          ke += bodies[i].translationalKineticEnergy() + bodies[i].rotationalKineticEnergy();
        }
        if (threads == 1) {
          oneThread = wall;
          reference.assign(bodies.begin(), bodies.end());
        }
        std::printf("| %s | %d | 1/%.0f | %ld | %d | %.1f | %.2f | %.2e | %.2e | %.2e | %s |\n", name, dynamic, 1 / dt,
                    sim.stepsDone(), threads, 1e6 * wall / sim.stepsDone(), oneThread / wall, drift, ke, penetration,
                    threads == 1 ? "-" : (equal ? "yes" : "NO"));
        std::fflush(stdout);
      }
    }
  }
}

void pour(const Registry& registry, double seconds) {
  const std::string dir = (std::filesystem::temp_directory_path() / "monolith_pour").string();
  std::filesystem::create_directories(dir);
  const std::string cmd = "python3 " + kScenes + "generate_contact_scenes.py " + dir + " --pour 250 1000 4000";
  if (std::system(cmd.c_str()) != 0) {
    std::fprintf(stderr, "could not run %s\n", cmd.c_str());
    return;
  }
  std::printf("\n| N spheres | threads | steps | us/step | us/sphere-step | speed-up | max penetration / size | 1T == 2T |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (int n : {250, 1000, 4000}) {
    char end[64];
    std::snprintf(end, sizeof end, "%.17g", seconds);
    const SceneSpec scene = loadScene(dir + "/pour_spheres_" + std::to_string(n) + ".json", {{"time.end", end}});
    double oneThread = 0;
    std::vector<RigidBody<3>> reference;
    for (int threads : {1, 2}) {
      Simulation<3> sim(scene, registry, threads);
      double penetration = 0;
      const auto t0 = std::chrono::steady_clock::now();
      while (!sim.finished()) penetration = std::max(penetration, sim.step().at("max_penetration_ratio"));
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const auto& bodies = sim.world().pool<RigidBody<3>>().components();
      bool equal = true;
      if (threads == 1) {
        oneThread = wall;
        reference.assign(bodies.begin(), bodies.end());
      } else {
        for (std::size_t i = 0; i < bodies.size(); ++i)
          equal = equal && std::memcmp(bodies[i].x.data(), reference[i].x.data(), 3 * sizeof(double)) == 0 &&
                  std::memcmp(bodies[i].v.data(), reference[i].v.data(), 3 * sizeof(double)) == 0;
      }
      const double us = 1e6 * wall / sim.stepsDone();
      std::printf("| %d | %d | %ld | %.0f | %.3f | %.2f | %.2e | %s |\n", n, threads, sim.stepsDone(), us, us / n,
                  oneThread / wall, penetration, threads == 1 ? "-" : (equal ? "yes" : "NO"));
      std::fflush(stdout);
    }
  }
}

// mixed_pile (every 3-D shape in one settling pile): us/step on 1 and 2 threads, deepest
// overlap over the smaller body's size, kinetic energy at the end (settling), bitwise 1T == 2T.
void mixedPile(const Registry& registry) {
  const SceneSpec scene = loadScene(kScenes + "mixed_pile.json");
  std::printf("\n| scene | bodies | threads | steps | us/step | speed-up | max penetration / size | final KE | 1T == 2T |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  double oneThread = 0;
  std::vector<RigidBody<3>> reference;
  for (int threads : {1, 2}) {
    Simulation<3> sim(scene, registry, threads);
    double penetration = 0;
    const auto t0 = std::chrono::steady_clock::now();
    while (!sim.finished()) penetration = std::max(penetration, sim.step().at("max_penetration_ratio"));
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const auto& bodies = sim.world().pool<RigidBody<3>>().components();
    double ke = 0;
    int dynamic = 0;
    bool equal = true;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      if (threads == 2)
        equal = equal && std::memcmp(bodies[i].x.data(), reference[i].x.data(), 3 * sizeof(double)) == 0 &&
                std::memcmp(bodies[i].v.data(), reference[i].v.data(), 3 * sizeof(double)) == 0;
      if (bodies[i].isStatic) continue;
      ++dynamic;
      ke += bodies[i].translationalKineticEnergy() + bodies[i].rotationalKineticEnergy();
    }
    if (threads == 1) {
      oneThread = wall;
      reference.assign(bodies.begin(), bodies.end());
    }
    std::printf("| mixed_pile | %d | %d | %ld | %.0f | %.2f | %.2e | %.2e | %s |\n", dynamic, threads, sim.stepsDone(),
                1e6 * wall / sim.stepsDone(), oneThread / wall, penetration, ke,
                threads == 1 ? "-" : (equal ? "yes" : "NO"));
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const std::string what = argc > 1 ? argv[1] : "all";
  const double seconds = argc > 2 ? std::atof(argv[2]) : 0.0;  // 0: the default of each group
  Registry registry;
  registerBuiltins(registry);
  std::vector<Override> extra;
  for (int i = 4; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto eq = arg.find('=');
    if (eq == std::string::npos) {
      std::fprintf(stderr, "expected key=value, got %s\n", argv[i]);
      return 2;
    }
    extra.push_back({arg.substr(0, eq), arg.substr(eq + 1)});
  }
  if (what == "pyramid" || what == "all") pyramids(registry, seconds, argc > 3 ? argv[3] : "", extra);
  if (what == "pour" || what == "all") pour(registry, seconds > 0 ? seconds : 1.0);
  if (what == "mixed" || what == "all") mixedPile(registry);
  return 0;
}

// Deformable benchmarks (speed against error), run by hand:
//  cantilever [edges...]: the cantilever scene at several mesh edges, corotated and
//    neo-Hookean: tip deflection against Euler-Bernoulli q L^4 / (8 E I), its error, the observed
//    order between successive meshes, substeps per frame and wall time per step;
//  scene NAME [end]: any deformable scene, seconds per frame and substeps per frame (Table 4.1).
//
// usage: bench_deformables cantilever [end, default 0.6] [edge ...]   (default 0.025 0.0125 0.00625)
//        bench_deformables scene NAME.json [end]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "components/deformable.h"
#include "scenarios/simulation.h"

using namespace monolith;

namespace {

const std::string kScenes = std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes/";

struct Measured {
  double tip = 0, seconds = 0, kinetic = 0;
  long steps = 0;
  int elements = 0;
};

Measured runCantilever(const Registry& registry, const std::string& model, double edge, double end) {
  const SceneSpec spec = loadScene(kScenes + "cantilever.json",
                                   {{"entities.bar.deformable.model", "\"" + model + "\""},
                                    {"entities.bar.deformable.mesh.box.edge_length", std::to_string(edge)},
                                    {"time.end", std::to_string(end)}});
  Simulation<2> sim(spec, registry, 1);
  Measured m;
  const auto start = std::chrono::steady_clock::now();
  std::map<std::string, double> last;
  while (!sim.finished()) last = sim.step();
  m.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  m.steps = sim.stepsDone();
  m.kinetic = last["kinetic_energy"];
  const Entity e = *sim.world().find("bar");
  const auto& p = *sim.world().template get<Particles<2>>(e);
  const auto& mesh = *sim.world().template get<SimplexMesh<2>>(e);
  m.elements = mesh.elementCount();
  double sum = 0;
  int n = 0;
  for (int i = 0; i < p.count(); ++i)
    if (mesh.restX[2 * i] > 0.5 - 1e-9) {  // the free end
      sum += p.x[2 * i + 1] - mesh.restX[2 * i + 1];
      ++n;
    }
  m.tip = -sum / n;
  return m;
}

int cantilever(int argc, char** argv) {
  const double end = argc > 2 ? std::atof(argv[2]) : 0.6;
  std::vector<double> edges;
  for (int i = 3; i < argc; ++i) edges.push_back(std::atof(argv[i]));
  if (edges.empty()) edges = {0.025, 0.0125, 0.00625};
  Registry registry;
  registerBuiltins(registry);
  const double rho = 1000, g = 9.81, L = 1, h = 0.1, E = 1e8;
  const double exact = 1.5 * rho * g * L * L * L * L / (E * h * h);
  std::printf("cantilever: Euler-Bernoulli tip deflection %.6f mm, end %.3g s, 1 thread\n\n", 1e3 * exact, end);
  std::printf("| model | edge (m) | triangles | tip (mm) | error | observed order | substeps/frame | ms/step | kinetic at end (J) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (const char* model : {"corotated", "neo_hookean"}) {
    double prevErr = 0, prevEdge = 0;
    for (double edge : edges) {
      const Measured m = runCantilever(registry, model, edge, end);
      const double err = (m.tip - exact) / exact;
      char order[32] = "";
      if (prevEdge > 0) std::snprintf(order, sizeof order, "%.2f", std::log(std::abs(prevErr / err)) / std::log(prevEdge / edge));
      std::printf("| %s | %g | %d | %.4f | %+.2f %% | %s | %.1f | %.3f | %.2e |\n", model, edge, m.elements, 1e3 * m.tip,
                  100 * err, order, m.steps / (end * 30), 1e3 * m.seconds / m.steps, m.kinetic);
      std::fflush(stdout);
      prevErr = err;
      prevEdge = edge;
    }
  }
  return 0;
}

int scene(int argc, char** argv) {
  if (argc < 3) return 2;
  Registry registry;
  registerBuiltins(registry);
  std::vector<Override> overrides;
  if (argc > 3) overrides.push_back({"time.end", argv[3]});
  const SceneSpec spec = loadScene(kScenes + argv[2], overrides);
  Simulation<3> sim(spec, registry);
  const auto start = std::chrono::steady_clock::now();
  int maxCg = 0;
  while (!sim.finished()) {
    const auto& m = sim.step();
    for (const char* k : {"deformable_cg_iterations", "deformable_cg_iterations_half"}) {
      const auto it = m.find(k);
      if (it != m.end()) maxCg = std::max(maxCg, static_cast<int>(it->second));
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double frames = spec.frameInterval > 0 ? spec.endTime / spec.frameInterval : spec.endTime * 30;
  std::printf("| %s | %.3g s | %ld | %.1f | %.3f | %d |\n", argv[2], spec.endTime, sim.stepsDone(),
              sim.stepsDone() / frames, seconds / frames, maxCg);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string what = argc > 1 ? argv[1] : "cantilever";
  if (what == "cantilever") return cantilever(argc, argv);
  if (what == "scene") return scene(argc, argv);
  std::fprintf(stderr, "usage: bench_deformables cantilever [end] [edge...] | scene NAME.json [end]\n");
  return 2;
}

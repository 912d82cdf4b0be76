// Deformable benchmarks (speed against error), run by hand:
//  cantilever [edges...]: the cantilever scene at several mesh edges, corotated and
//    neo-Hookean: tip deflection against Euler-Bernoulli q L^4 / (8 E I), its error, the observed
//    order between successive meshes, substeps per frame and wall time per step;
//  scene NAME [end]: any deformable scene, seconds per frame and substeps per frame (Table 4.1).
//
//  cantilever3d [cells...]: the same in 3-D (cantilever_3d), meshes given as cells per axis;
//
// usage: bench_deformables cantilever [end, default 0.6] [edge ...]   (default 0.025 0.0125 0.00625)
//        bench_deformables cantilever3d [end] [nx,ny,nz ...]          (default 40,4,1 80,8,1 120,12,1)
//        a model name (corotated, neo_hookean) among the meshes runs only that model, cfl=C
//        overrides the scene's CFL number (the equilibrium does not depend on it)
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

// A mesh given as cells per axis ("40,8") rather than an edge length ("0.025").
bool isCells(const std::string& mesh) { return mesh.find(',') != std::string::npos; }

// Tip deflection of the cantilever scene (2-D) or cantilever_3d (3-D): the mean downward
// displacement of the free end's vertices once the mass damping has brought the bar to rest.
template <int d>
Measured runCantilever(const Registry& registry, const std::string& model, const std::string& mesh, double end,
                       const std::string& cfl) {
  const std::string meshKey = "entities.bar.deformable.mesh.box";
  const SceneSpec spec =
      loadScene(kScenes + (d == 2 ? "cantilever.json" : "cantilever_3d.json"),
                {{"entities.bar.deformable.model", "\"" + model + "\""},
                 {meshKey, std::string(d == 2 ? "{\"half_extents\": [0.5, 0.05], " : "{\"half_extents\": [0.5, 0.05, 0.05], ") +
                               (isCells(mesh) ? "\"cells\": [" + mesh + "]}" : "\"edge_length\": " + mesh + "}")},
                 {"time.end", std::to_string(end)},
                 {"time.cfl", cfl}});
  Simulation<d> sim(spec, registry, 1);
  Measured m;
  const auto start = std::chrono::steady_clock::now();
  std::map<std::string, double> last;
  while (!sim.finished()) last = sim.step();
  m.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  m.steps = sim.stepsDone();
  m.kinetic = last["kinetic_energy"];
  const Entity e = *sim.world().find("bar");
  const auto& p = *sim.world().template get<Particles<d>>(e);
  const auto& mesh_ = *sim.world().template get<SimplexMesh<d>>(e);
  m.elements = mesh_.elementCount();
  double sum = 0;
  int n = 0;
  for (int i = 0; i < p.count(); ++i)
    if (mesh_.restX[d * i] > 0.5 - 1e-9) {  // the free end
      sum += p.x[d * i + 1] - mesh_.restX[d * i + 1];
      ++n;
    }
  m.tip = -sum / n;
  return m;
}

// Meshes: edge lengths ("0.025") or cell counts per axis ("40,8" in 2-D, "40,8,2" in 3-D).
template <int d>
int cantilever(int argc, char** argv) {
  const double end = argc > 2 ? std::atof(argv[2]) : 0.6;
  std::vector<std::string> meshes, models;
  std::string cfl = "0.5";
  for (int i = 3; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("cfl=", 0) == 0) cfl = a.substr(4);
    else (a == "corotated" || a == "neo_hookean" ? models : meshes).push_back(a);
  }
  if (models.empty()) models = {"corotated", "neo_hookean"};
  if (meshes.empty())
    meshes = d == 2 ? std::vector<std::string>{"0.025", "0.0125", "0.00625"}
                    : std::vector<std::string>{"40,4,1", "80,8,1", "120,12,1"};
  Registry registry;
  registerBuiltins(registry);
  const double rho = 1000, g = 9.81, L = 1, h = 0.1, E = 1e8;
  const double exact = 1.5 * rho * g * L * L * L * L / (E * h * h);
  std::printf("cantilever (%d-D): Euler-Bernoulli tip deflection %.6f mm, end %.3g s, cfl %s, 1 thread\n\n", d, 1e3 * exact,
              end, cfl.c_str());
  std::printf("| model | %s | %s | tip (mm) | error | observed order | substeps/frame | ms/step | s total | kinetic at end (J) |\n",
              "mesh (edge or cells)", d == 2 ? "triangles" : "tetrahedra");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& model : models) {
    double prevErr = 0, prevSize = 0;
    for (const std::string& mesh : meshes) {
      const Measured m = runCantilever<d>(registry, model, mesh, end, cfl);
      const double err = (m.tip - exact) / exact;
      // Mesh size: the edge, or the cell height through the thickness.
      const double size = isCells(mesh) ? h / std::atof(mesh.substr(mesh.find(',') + 1).c_str()) : std::atof(mesh.c_str());
      char order[32] = "";
      if (prevSize > 0) std::snprintf(order, sizeof order, "%.2f", std::log(std::abs(prevErr / err)) / std::log(prevSize / size));
      std::printf("| %s | %s | %d | %.4f | %+.2f %% | %s | %.1f | %.3f | %.1f | %.2e |\n", model.c_str(), mesh.c_str(), m.elements,
                  1e3 * m.tip, 100 * err, order, m.steps / (end * 30), 1e3 * m.seconds / m.steps, m.seconds, m.kinetic);
      std::fflush(stdout);
      prevErr = err;
      prevSize = size;
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
  if (what == "cantilever") return cantilever<2>(argc, argv);
  if (what == "cantilever3d") return cantilever<3>(argc, argv);
  if (what == "scene") return scene(argc, argv);
  std::fprintf(stderr, "usage: bench_deformables cantilever [end] [edge...] | cantilever3d [end] [nx,ny,nz...] | "
                       "scene NAME.json [end]\n");
  return 2;
}

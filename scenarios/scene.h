#pragma once
// Scene files (DESIGN.md §7): JSON with comments. loadScene() reads and validates the
// top-level settings; populateWorld() validates and creates the entities through the
// component factories of the registry. Every problem is a SceneError naming the file, the JSON
// path and what was expected; nothing is simulated from a scene that fails validation.
#include <string>
#include <utility>
#include <vector>

#include "ecs/config.h"
#include "ecs/registry.h"
#include "ecs/world.h"

namespace monolith {

// A point where the fluid velocity and pressure are recorded every step (probes.csv).
struct ProbeSpec {
  std::string name;
  std::vector<double> position;
  std::string path;  // JSON path, for the error when the point lies outside the grid
};
// A line sampled at every frame (profiles/<name>_<step>.csv), e.g. a cavity centre line.
struct ProfileSpec {
  std::string name;
  std::vector<double> from, to;
  int points = 2;
  std::string path;
};

// Where a fixed-dt scene's clock counts from: t^n = time + (n - step) dt. It is (0, 0), so that
// t^n = n dt exactly, unless `monolith resume --set time.dt=...` changed the step of a run: then
// it is the checkpoint's (step, time), and the run continues from there at the new dt.
struct ClockOrigin {
  long step = 0;
  double time = 0;
};

struct SceneSpec {
  std::string file;       // the path as given (used in messages)
  std::string directory;  // relative paths in the scene are resolved against this
  Json json;              // the scene after --set overrides
  std::string description;
  int dimension = 3;
  double dt = 0;
  long steps = 0;        // fixed-dt scenes (counted from step 0); 0 when the step follows the CFL condition
  ClockOrigin clock;     // fixed-dt scenes
  double endTime = 0;    // simulated time at the end
  double cfl = 0;        // > 0: adaptive step, dt = cfl * (smallest unit-CFL step of the systems)
  long frameEvery = 1;   // fixed dt: write a frame every this many steps (0: no frames)
  double frameInterval = 0;  // CFL scenes: write a frame every this much simulated time
  int threads = 2;
  std::string outputDirectory;  // "" = derived from the scene name
  std::vector<ProbeSpec> probes;
  std::vector<ProfileSpec> profiles;
  std::vector<std::string> plugins;  // resolved paths
  long checkpointEvery = 0;          // 0 = off
  double guardMaxAbs = 1e12;         // blow-up guard: any state value beyond this is absurd
  std::string stopDiagnostic;        // "stop": end the run early once this diagnostic ...
  double stopBelow = 0;              // ... falls below this value (steady state reached)
};

// One "--set key=value": key is a dotted path (entity names may stand for their index in
// "entities", e.g. entities.ball.rigid_body.mass=2); value is JSON or else a plain string.
using Override = std::pair<std::string, std::string>;

// Parses the file (comments allowed), applies the overrides and validates the top level.
SceneSpec loadScene(const std::string& path, const std::vector<Override>& overrides = {});
// Same, from text already in memory (checkpoints carry their scene). `clock`: the origin a
// fixed-dt scene's "end" is counted from (a resumed run's, see ClockOrigin).
SceneSpec parseScene(const std::string& text, const std::string& file, const std::vector<Override>& overrides = {},
                     const ClockOrigin& clock = {});

// Creates the scene's entities in `world` (which must be empty) and sets the world settings.
template <int d>
void populateWorld(const SceneSpec& scene, const Registry& registry, World<d>& world);

// Loads the plugins the scene names into the registry (PluginError names the path).
class PluginLoader;
void loadScenePlugins(const SceneSpec& scene, PluginLoader& loader, Registry& registry);

}  // namespace monolith

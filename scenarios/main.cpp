// The monolith command-line tool. See `monolith help`.
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "ecs/plugin.h"
#include "ecs/registry.h"
#include "ecs/scheduler.h"
#include "scenarios/plugin_search.h"
#include "scenarios/runner.h"
#include "scenarios/scene.h"

using namespace monolith;

namespace {

const char* kUsage =
    "usage:\n"
    "  monolith run SCENE [--out DIR] [--threads N] [--set key=value]... [--checkpoint-every K]\n"
    "                     [--plugin NAME|PATH]... [--no-frames] [--quiet] [--check]\n"
    "  monolith resume CHECKPOINT [--out DIR] [--threads N] [--set time.KEY=value]... [--checkpoint-every K]\n"
    "                            [--plugin NAME|PATH]... [--quiet]\n"
    "  monolith validate SCENE [--set key=value]... [--plugin NAME|PATH]...\n"
    "  monolith graph SCENE          print the step's task graph (Graphviz DOT)\n"
    "  monolith systems [--plugin NAME|PATH]...   list component and system types\n"
    "  monolith version\n"
    "exit codes: 0 ok, 1 runtime/I-O failure, 2 bad command line, 3 scene/plugin/checkpoint rejected,\n"
    "            4 simulation unstable (stopped by the blow-up guard), 5 a scene check failed (run --check)\n";

struct Args {
  std::string command, target;
  RunOptions run;
  std::vector<Override> overrides;
  std::vector<std::string> plugins;
  bool check = false;  // a failed scene check is exit code 5
};

[[noreturn]] void usageError(const std::string& message) {
  std::fprintf(stderr, "monolith: %s\n%s", message.c_str(), kUsage);
  std::exit(kExitUsage);
}

long parseCount(const std::string& flag, const std::string& value, long min) {
  try {
    std::size_t used = 0;
    const long v = std::stol(value, &used);
    if (used == value.size() && v >= min) return v;
  } catch (const std::exception&) {
  }
  usageError(flag + " needs an integer >= " + std::to_string(min) + ", got '" + value + "'");
}

Args parseArgs(int argc, char** argv) {
  Args a;
  if (argc < 2) usageError("no command given");
  a.command = argv[1];
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usageError(arg + " needs a value");
      return argv[++i];
    };
    if (arg == "--out") a.run.outDir = value();
    else if (arg == "--threads") a.run.threads = static_cast<int>(parseCount(arg, value(), 1));
    else if (arg == "--checkpoint-every") a.run.checkpointEvery = parseCount(arg, value(), 0);
    else if (arg == "--plugin") a.plugins.push_back(value());
    else if (arg == "--no-frames") a.run.writeFrames = false;
    else if (arg == "--quiet") a.run.progress = false;
    else if (arg == "--check") a.check = true;
    else if (arg == "--set") {
      const std::string kv = value();
      const auto eq = kv.find('=');
      if (eq == std::string::npos || eq == 0) usageError("--set needs key=value, got '" + kv + "'");
      a.overrides.emplace_back(kv.substr(0, eq), kv.substr(eq + 1));
    } else if (!arg.empty() && arg[0] == '-') usageError("unknown option " + arg);
    else if (a.target.empty()) a.target = arg;
    else usageError("unexpected argument '" + arg + "'");
  }
  return a;
}

void listTypes(const Registry& registry) {
  auto print = [](const auto& list, const char* kind, int d) {
    std::printf("%s (%d-D):\n", kind, d);
    for (const auto& t : list)
      std::printf("  %-30s %s%s\n", t.name.c_str(), t.summary.c_str(),
                  t.origin == "built-in" ? "" : ("  [" + t.origin + "]").c_str());
  };
  print(registry.components<3>(), "components", 3);
  print(registry.systems<3>(), "systems", 3);
  print(registry.components<2>(), "components", 2);
  print(registry.systems<2>(), "systems", 2);
}

template <int d>
int printGraph(const SceneSpec& scene, const Registry& registry) {
  World<d> world;
  populateWorld(scene, registry, world);
  Scheduler<d> scheduler(registry.instantiateSystems<d>(), world, 1);
  std::cout << scheduler.dot();
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parseArgs(argc, argv);
  if (args.command == "help" || args.command == "--help" || args.command == "-h") {
    std::printf("%s", kUsage);
    return kExitOk;
  }
  if (args.command == "version" || args.command == "--version") {
    std::printf("monolith %s\n", MONOLITH_VERSION);
    return kExitOk;
  }

  Registry registry;
  registerBuiltins(registry);
  PluginLoader plugins;
  for (const auto& p : args.plugins) {
    try {
      plugins.load(isPluginName(p) ? findPlugin(p) : p, registry);  // a bare name is searched for
    } catch (const PluginError& e) {
      std::fprintf(stderr, "monolith: %s\n", e.what());
      return kExitInvalidScene;
    } catch (const std::runtime_error& e) {  // a name not found
      std::fprintf(stderr, "monolith: --plugin %s: %s\n", p.c_str(), e.what());
      return kExitInvalidScene;
    }
  }
  if (args.command == "systems") {
    listTypes(registry);
    return kExitOk;
  }
  if (args.command != "run" && args.command != "validate" && args.command != "resume" && args.command != "graph")
    usageError("unknown command '" + args.command + "'");
  if (args.target.empty()) usageError(args.command + " needs a " + (args.command == "resume" ? "CHECKPOINT" : "SCENE"));

  if (args.command == "resume") {
    for (const auto& o : args.overrides)
      if (!resumeMayChange(o.first))
        usageError(std::string("resume --set changes only time settings (") + kResumeSettings + "), got '" + o.first + "'");
    const RunResult r = resumeRun(args.target, registry, plugins, args.run, args.overrides);
    if (r.exitCode != kExitOk) {
      std::fprintf(stderr, "monolith: %s\n", r.message.c_str());
      return r.exitCode;
    }
    std::printf("resumed run written to %s\n", r.outDir.c_str());
    return kExitOk;
  }

  SceneSpec scene;
  try {
    scene = loadScene(args.target, args.overrides);
    if (args.command == "validate" || args.command == "graph") {
      loadScenePlugins(scene, plugins, registry);
      if (args.command == "graph")
        return scene.dimension == 2 ? printGraph<2>(scene, registry) : printGraph<3>(scene, registry);
      if (scene.dimension == 2) {
        World<2> w;
        populateWorld(scene, registry, w);
      } else {
        World<3> w;
        populateWorld(scene, registry, w);
      }
      std::printf("%s: valid (%d-D, %ld steps of dt = %g)\n", args.target.c_str(), scene.dimension, scene.steps, scene.dt);
      return kExitOk;
    }
  } catch (const SceneError& e) {
    std::fprintf(stderr, "monolith: %s\n", e.what());
    return kExitInvalidScene;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "monolith: %s\n", e.what());
    return kExitInvalidScene;
  }

  const RunResult r = runScene(scene, registry, plugins, args.run);
  if (r.exitCode != kExitOk) {
    std::fprintf(stderr, "monolith: %s\n", r.message.c_str());
    if (!r.outDir.empty()) std::fprintf(stderr, "monolith: outputs so far are in %s\n", r.outDir.c_str());
    return r.exitCode;
  }
  std::printf("run written to %s (%ld steps, %.3f s of stepping)\n", r.outDir.c_str(), r.stepsCompleted, r.wallSeconds);
  std::printf("%s", formatChecks(r.checks).c_str());
  if (args.check && !r.checksPass()) {
    std::fprintf(stderr, "monolith: a check failed\n");
    return kExitCheckFailed;
  }
  return kExitOk;
}

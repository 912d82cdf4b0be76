// The monolith command-line tool. See `monolith help`.
#include <cstdio>
#include <cstring>
#include <unistd.h>
#include <iostream>
#include <string>
#include <vector>

#include "ecs/plugin.h"
#include "ecs/registry.h"
#include "ecs/scheduler.h"
#include "scenarios/plugin_search.h"
#include "scenarios/runner.h"
#include "scenarios/scene.h"
#include "scenarios/sweep.h"

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
    "  monolith sweep SCENE --vary KEY=V1,V2,... [--vary ...] [--set key=value]... [--repeat N] [--jobs J]\n"
    "                       [--threads T] --out DIR [--point K | --emit-slurm]\n"
    "  monolith sweep --collect DIR   build DIR/sweep.csv from the points run so far (e.g. by Slurm)\n"
    "  monolith bench [SUITE] [--threads 1,2] [--repeat N] [--out DIR]   (default suite: scenarios/bench/default.json)\n"
    "  monolith plot RUN_DIR|SWEEP_CSV [--x COL] [--y COL]... [--logx] [--logy] [--out PNG]\n"
    "  monolith plot RUN_DIR --frame [TIME] [--field speed|vorticity|pressure|...] [--view=AZ,EL] [--out PNG]\n"
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

std::string selfExecutable(const char* argv0) {
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string(argv0);
}

int sweepCommand(int argc, char** argv) {
  SweepOptions o;
  o.executable = selfExecutable(argv[0]);
  std::string collect;
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usageError(arg + " needs a value");
      return argv[++i];
    };
    auto keyValue = [&](const std::string& kv) {
      const auto eq = kv.find('=');
      if (eq == std::string::npos || eq == 0 || eq + 1 == kv.size()) usageError(arg + " needs KEY=VALUE, got '" + kv + "'");
      return std::make_pair(kv.substr(0, eq), kv.substr(eq + 1));
    };
    if (arg == "--vary") {
      const auto [key, list] = keyValue(value());
      std::vector<std::string> values;
      std::size_t start = 0;
      for (std::size_t comma; (comma = list.find(',', start)) != std::string::npos; start = comma + 1)
        values.push_back(list.substr(start, comma - start));
      values.push_back(list.substr(start));
      for (const auto& v : values)
        if (v.empty()) usageError("--vary " + key + ": an empty value in '" + list + "'");
      o.vary.emplace_back(key, values);
    } else if (arg == "--set") o.sets.push_back(keyValue(value()));
    else if (arg == "--repeat") o.repeat = static_cast<int>(parseCount(arg, value(), 1));
    else if (arg == "--jobs") o.jobs = static_cast<int>(parseCount(arg, value(), 1));
    else if (arg == "--threads") o.threads = static_cast<int>(parseCount(arg, value(), 1));
    else if (arg == "--out") o.out = value();
    else if (arg == "--point") o.point = parseCount(arg, value(), 0);
    else if (arg == "--emit-slurm") o.emitSlurm = true;
    else if (arg == "--collect") collect = value();
    else if (!arg.empty() && arg[0] == '-') usageError("unknown sweep option " + arg);
    else if (o.scene.empty()) o.scene = arg;
    else usageError("unexpected argument '" + arg + "'");
  }
  if (!collect.empty()) return collectSweep(collect);
  if (o.scene.empty()) usageError("sweep needs a SCENE (or --collect DIR)");
  if (o.out.empty()) usageError("sweep needs --out DIR");
  if (o.point >= 0 && o.emitSlurm) usageError("--point and --emit-slurm exclude each other");
  try {  // a scene that cannot load is refused before any point runs
    loadScene(o.scene, o.sets);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "monolith: %s\n", e.what());
    return kExitInvalidScene;
  }
  return runSweep(o);
}

int benchCommand(int argc, char** argv) {
  BenchOptions o;
  o.executable = selfExecutable(argv[0]);
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usageError(arg + " needs a value");
      return argv[++i];
    };
    if (arg == "--threads") {
      o.threads.clear();
      const std::string list = value();
      std::size_t start = 0;
      for (std::size_t comma = 0; comma != std::string::npos; start = comma + 1) {
        comma = list.find(',', start);
        o.threads.push_back(static_cast<int>(parseCount(arg, list.substr(start, comma - start), 1)));
      }
    } else if (arg == "--repeat") o.repeat = static_cast<int>(parseCount(arg, value(), 1));
    else if (arg == "--out") o.out = value();
    else if (!arg.empty() && arg[0] == '-') usageError("unknown bench option " + arg);
    else if (o.suite.empty()) o.suite = arg;
    else usageError("unexpected argument '" + arg + "'");
  }
  return runBench(o);
}

}  // namespace

#ifndef MONOLITH_SOURCE_TREE
#define MONOLITH_SOURCE_TREE "."
#endif

// `monolith plot ...`: hands the arguments to scenarios/plot.py (Debian's python3-matplotlib).
int plotCommand(int argc, char** argv) {
  const char* env = std::getenv("MONOLITH_PLOT_SCRIPT");
  const std::string script = env ? env : std::string(MONOLITH_SOURCE_TREE) + "/scenarios/plot.py";
  std::vector<char*> args = {const_cast<char*>("/usr/bin/python3"), const_cast<char*>(script.c_str())};
  for (int i = 2; i < argc; ++i) args.push_back(argv[i]);
  args.push_back(nullptr);
  execv("/usr/bin/python3", args.data());
  std::fprintf(stderr, "monolith: plot needs /usr/bin/python3 with matplotlib (apt-get install python3-matplotlib)\n");
  return kExitFailure;
}

int main(int argc, char** argv) {
  if (argc >= 2 && std::strcmp(argv[1], "plot") == 0) return plotCommand(argc, argv);
  if (argc >= 2 && std::strcmp(argv[1], "sweep") == 0) return sweepCommand(argc, argv);
  if (argc >= 2 && std::strcmp(argv[1], "bench") == 0) return benchCommand(argc, argv);
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

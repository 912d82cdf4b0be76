#pragma once
// Runs a scene: builds the world and the scheduler, steps, guards against blow-up, writes the
// run directory (metrics.csv, summary.json, frames + .pvd, checkpoints) and reports progress.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "ecs/plugin.h"
#include "ecs/registry.h"
#include "scenarios/checks.h"
#include "scenarios/scene.h"

namespace monolith {

// Process exit codes of the CLI (also returned by runScene).
enum ExitCode : int {
  kExitOk = 0,
  kExitFailure = 1,      // I/O or internal error
  kExitUsage = 2,        // bad command line
  kExitInvalidScene = 3, // scene, plugin or checkpoint rejected before simulating
  kExitUnstable = 4,     // the blow-up guard stopped the run
  kExitCheckFailed = 5,  // run --check: the run completed but a scene check failed
};

struct RunOptions {
  std::string outDir;          // "" = scene's output.directory, else runs/<scene name>[-k]
  int threads = 0;             // 0 = the scene's "threads"
  long checkpointEvery = -1;   // -1 = the scene's checkpoint.every
  bool progress = true;        // progress bar (TTY) or plain lines on stderr
  bool writeFrames = true;
};

struct RunResult {
  int exitCode = kExitOk;
  std::string message;  // diagnosis when exitCode != 0
  std::string outDir;
  long stepsCompleted = 0;
  std::uint64_t stateHash = 0;
  double wallSeconds = 0;
  std::vector<CheckResult> checks;  // the scene's checks, evaluated at the end
  bool checksPass() const {
    for (const auto& c : checks)
      if (!c.pass) return false;
    return true;
  }
};

RunResult runScene(const SceneSpec& scene, Registry& registry, PluginLoader& plugins, const RunOptions& options);
// The settings `monolith resume --set` may change: the "time" keys (end, steps, dt, cfl,
// frame_rate). Everything else is the checkpointed run's own.
bool resumeMayChange(const std::string& key);
inline constexpr const char* kResumeSettings = "time.end, time.steps, time.dt, time.cfl, time.frame_rate";

// Continues the run a checkpoint was taken from (to the scene's end). `timeOverrides` ("--set
// time.KEY=value" only) move the end or change the step: with a new fixed dt the clock goes on
// from the checkpoint's time, t = t_ckpt + (n - n_ckpt) dt (see ClockOrigin).
RunResult resumeRun(const std::string& checkpointPath, Registry& registry, PluginLoader& plugins, RunOptions options,
                    const std::vector<Override>& timeOverrides = {});

}  // namespace monolith

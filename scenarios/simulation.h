#pragma once
// A scene made ready to step: its world, populated from the scene, and the scheduler of the
// systems it needs. The runner (CLI), the tests and the benchmarks all step scenes through
// this one class, so they measure the same code.
#include <map>
#include <memory>
#include <string>

#include "ecs/registry.h"
#include "ecs/scheduler.h"
#include "scenarios/scene.h"

namespace monolith {

template <int d>
class Simulation {
 public:
  // threads <= 0: the scene's "threads".
  Simulation(const SceneSpec& scene, const Registry& registry, int threads = 0);

  // Advances one step from t^n; returns the step's diagnostics. Fixed-dt scenes step by dt
  // (t^n = n dt exactly, or counted from the scene's clock origin); CFL scenes by nextDt().
  const std::map<std::string, double>& step();
  long stepsDone() const { return stepsDone_; }
  double time() const { return time_; }
  double lastDt() const { return lastDt_; }
  // The step the next call to step() will take.
  double nextDt() const;
  bool finished() const;
  // Fraction of the simulated time done, for progress reports.
  double progress() const { return scene_.endTime > 0 ? time_ / scene_.endTime : 1.0; }
  // True when the last step ended on a frame time (every frameEvery steps, or every
  // frameInterval of simulated time for CFL scenes, whose steps are clipped to land on it).
  bool frameDue() const { return frameDue_; }
  // After restoring a checkpoint taken after `steps` steps at `time`.
  void restoreClock(long steps, double time);

  World<d>& world() { return world_; }
  const World<d>& world() const { return world_; }
  Scheduler<d>& scheduler() { return *scheduler_; }
  const SceneSpec& scene() const { return scene_; }
  // Rebuilds the task graph (after the set of component types changed, e.g. on restore).
  void reschedule();

 private:
  double fixedTime(long steps) const;  // t^steps of a fixed-dt scene

  SceneSpec scene_;
  const Registry& registry_;
  int threads_;
  World<d> world_;
  std::unique_ptr<Scheduler<d>> scheduler_;
  long stepsDone_ = 0;
  double time_ = 0, lastDt_ = 0;
  long framesDone_ = 0;  // CFL scenes: frame times k * frameInterval reached so far
  bool frameDue_ = false;
  StepContext ctx_;
};

}  // namespace monolith

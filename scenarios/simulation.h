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

  // Advances one step from t^n = stepsDone() * dt; returns the step's diagnostics.
  const std::map<std::string, double>& step();
  long stepsDone() const { return stepsDone_; }
  void setStepsDone(long n) { stepsDone_ = n; }  // after restoring a checkpoint
  double time() const { return stepsDone_ * scene_.dt; }

  World<d>& world() { return world_; }
  const World<d>& world() const { return world_; }
  Scheduler<d>& scheduler() { return *scheduler_; }
  const SceneSpec& scene() const { return scene_; }
  // Rebuilds the task graph (after the set of component types changed, e.g. on restore).
  void reschedule();

 private:
  SceneSpec scene_;
  const Registry& registry_;
  int threads_;
  World<d> world_;
  std::unique_ptr<Scheduler<d>> scheduler_;
  long stepsDone_ = 0;
  StepContext ctx_;
};

}  // namespace monolith

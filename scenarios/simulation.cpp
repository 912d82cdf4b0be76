#include "scenarios/simulation.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace monolith {

template <int d>
Simulation<d>::Simulation(const SceneSpec& scene, const Registry& registry, int threads)
    : scene_(scene), registry_(registry), threads_(threads > 0 ? threads : scene.threads) {
  populateWorld(scene_, registry_, world_);
  reschedule();
}

template <int d>
void Simulation<d>::reschedule() {
  scheduler_.reset();
  scheduler_ = std::make_unique<Scheduler<d>>(registry_.instantiateSystems<d>(), world_, threads_);
}

template <int d>
double Simulation<d>::nextDt() const {
  if (scene_.cfl <= 0) return scene_.dt;
  double unit = std::numeric_limits<double>::infinity();
  for (const auto* system : scheduler_->systems()) unit = std::min(unit, system->unitCflDt(world_));
  double dt = std::min(scene_.dt, scene_.cfl * unit);
  // Land exactly on the next frame time and on the end (no step beyond either).
  double target = scene_.endTime;
  if (scene_.frameInterval > 0) target = std::min(target, (framesDone_ + 1) * scene_.frameInterval);
  if (time_ + dt >= target - 1e-12 * std::max(1.0, target)) dt = target - time_;
  return dt;
}

template <int d>
double Simulation<d>::fixedTime(long steps) const {
  // With the origin (0, 0) this is steps * dt exactly (0 + x == x), as before resumes could
  // change dt.
  return scene_.clock.time + static_cast<double>(steps - scene_.clock.step) * scene_.dt;
}

template <int d>
bool Simulation<d>::finished() const {
  if (scene_.cfl <= 0) return stepsDone_ >= scene_.steps;
  return time_ >= scene_.endTime * (1 - 1e-14);
}

template <int d>
void Simulation<d>::restoreClock(long steps, double time) {
  stepsDone_ = steps;
  time_ = scene_.cfl > 0 ? time : fixedTime(steps);
  framesDone_ = scene_.frameInterval > 0 ? std::lround(std::floor(time_ / scene_.frameInterval + 1e-9)) : 0;
}

template <int d>
const std::map<std::string, double>& Simulation<d>::step() {
  const double dt = nextDt();
  ctx_.diagnostics.clear();
  ctx_.dt = dt;
  ctx_.time = time_;
  ctx_.step = stepsDone_;
  scheduler_->step(world_, ctx_);
  ++stepsDone_;
  lastDt_ = dt;
  if (scene_.cfl <= 0) {
    time_ = fixedTime(stepsDone_);  // from the index: no drift, identical after a resume
    frameDue_ = scene_.frameEvery > 0 && (stepsDone_ - scene_.clock.step) % scene_.frameEvery == 0;
  } else {
    time_ += dt;
    frameDue_ = false;
    if (scene_.frameInterval > 0) {
      const double frameTime = (framesDone_ + 1) * scene_.frameInterval;
      if (time_ >= frameTime - 1e-12 * std::max(1.0, frameTime)) {
        time_ = frameTime;  // the step was clipped to it: remove the rounding
        ++framesDone_;
        frameDue_ = true;
      }
    }
    if (time_ >= scene_.endTime * (1 - 1e-14)) time_ = scene_.endTime;
  }
  return ctx_.diagnostics.values();
}

template class Simulation<2>;
template class Simulation<3>;

}  // namespace monolith

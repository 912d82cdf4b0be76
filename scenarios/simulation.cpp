#include "scenarios/simulation.h"

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
const std::map<std::string, double>& Simulation<d>::step() {
  ctx_.diagnostics.clear();
  ctx_.dt = scene_.dt;
  ctx_.time = stepsDone_ * scene_.dt;  // t^n from the index: no drift, identical after a resume
  ctx_.step = stepsDone_;
  scheduler_->step(world_, ctx_);
  ++stepsDone_;
  return ctx_.diagnostics.values();
}

template class Simulation<2>;
template class Simulation<3>;

}  // namespace monolith

#pragma once
// Particles embedded in another deformable body's elements (components/deformable.h
// EmbeddedBinding; Sifakis et al. 2007 [138], hard bindings):
//  * the forces on an embedded particle act on its host element's particles with its barycentric
//    weights: the elastic force joins the host's explicit forces before the host's damping solve,
//    and the damping force the embedded body's solve puts on it (its velocity prescribed, projected
//    out of the CG like a bound particle's, Sec. 4.7.3) is given to them as an impulse after the
//    stage's solves (systems/deformable_dynamics.cpp). Since the weights sum to one and x = sum w x_i,
//    linear and angular momentum are kept;
//  * follow_embedded_hosts (Step IV and Step V, after every other system of the stage): the embedded
//    particles take the interpolated position and velocity of their host elements.
#include <memory>
#include <string>
#include <vector>

#include "components/deformable.h"
#include "ecs/system.h"

namespace monolith {

// Calls add(host entity, host particle, weight, embedded particle) for every weight of every
// embedded particle of `b` (hosts that no longer exist are skipped).
template <int d, class Add>
void forEachHostWeight(World<d>& world, const EmbeddedBinding<d>& b, Add add) {
  const std::vector<std::string> names = b.hostNames();
  for (std::size_t k = 0; k < b.particle.size(); ++k) {
    const auto host = world.find(names[b.host[k]]);
    const SimplexMesh<d>* mesh = host ? world.template get<SimplexMesh<d>>(*host) : nullptr;
    if (!mesh) continue;
    const int* v = &mesh->elements[(d + 1) * b.element[k]];
    for (int a = 0; a <= d; ++a) add(*host, v[a], b.weight[(d + 1) * k + a], b.particle[k]);
  }
}

// Sets the embedded particles' positions (if `positions`) and velocities from their hosts.
template <int d>
void followEmbeddedHosts(World<d>& world, bool positions);

template <int d>
class FollowEmbeddedHosts final : public System<d> {
 public:
  explicit FollowEmbeddedHosts(Stage s) : stage_(s) {}
  std::string name() const override {
    return stage_ == Stage::AdvancePositions ? "follow_embedded_hosts" : "follow_embedded_hosts_velocity";
  }
  Stage stage() const override { return stage_; }
  std::vector<std::string> reads() const override { return {EmbeddedBinding<d>::kName, SimplexMesh<d>::kName}; }
  std::vector<std::string> writes() const override { return {Particles<d>::kName}; }
  bool needed(const World<d>& w) const override { return w.template count<EmbeddedBinding<d>>() > 0; }
  void run(World<d>& world, StepContext&) override { followEmbeddedHosts(world, stage_ == Stage::AdvancePositions); }

 private:
  Stage stage_;
};

// The follow systems of Steps IV and V (the registry's "embedded_bindings", registered after
// every other deformable system so that they see the stage's last host positions and velocities).
template <int d>
std::vector<std::unique_ptr<System<d>>> makeEmbeddedBindingSystems();

}  // namespace monolith

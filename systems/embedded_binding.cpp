#include "systems/embedded_binding.h"

namespace monolith {

template <int d>
void followEmbeddedHosts(World<d>& world, bool positions) {
  world.template each<EmbeddedBinding<d>, Particles<d>>([&](Entity, EmbeddedBinding<d>& b, Particles<d>& p) {
    for (int i : b.particle)
      for (int a = 0; a < d; ++a) {
        if (positions) p.x[d * i + a] = 0;
        p.v[d * i + a] = 0;
      }
    forEachHostWeight<d>(world, b, [&](Entity host, int j, double w, int i) {
      const Particles<d>& h = *world.template get<Particles<d>>(host);
      for (int a = 0; a < d; ++a) {
        if (positions) p.x[d * i + a] += w * h.x[d * j + a];
        p.v[d * i + a] += w * h.v[d * j + a];
      }
    });
  });
}

template <int d>
std::vector<std::unique_ptr<System<d>>> makeEmbeddedBindingSystems() {
  std::vector<std::unique_ptr<System<d>>> out;
  out.push_back(std::make_unique<FollowEmbeddedHosts<d>>(Stage::AdvancePositions));
  out.push_back(std::make_unique<FollowEmbeddedHosts<d>>(Stage::AdvanceVelocity));
  return out;
}

template void followEmbeddedHosts<2>(World<2>&, bool);
template void followEmbeddedHosts<3>(World<3>&, bool);
template class FollowEmbeddedHosts<2>;
template class FollowEmbeddedHosts<3>;
template std::vector<std::unique_ptr<System<2>>> makeEmbeddedBindingSystems<2>();
template std::vector<std::unique_ptr<System<3>>> makeEmbeddedBindingSystems<3>();

}  // namespace monolith

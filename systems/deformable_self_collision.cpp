#include "systems/deformable_self_collision.h"


#include "components/cloth.h"

namespace monolith {

namespace dm = solvers::deformable;

template <int d>
void DeformableSelfCollision<d>::run(World<d>& world, StepContext& ctx) {
  std::vector<std::pair<std::uint64_t, int>> bodies;
  std::vector<Particles<d>*> particles;
  std::vector<Entity> entities;
  world.template each<Particles<d>, SurfaceCollision>([&](Entity e, Particles<d>& p, SurfaceCollision&) {
    bodies.emplace_back((std::uint64_t(e.index) << 32) | e.generation, p.count());
    particles.push_back(&p);
    entities.push_back(e);
  });
  if (bodies != bodies_) {
    surface_ = dm::CollisionSurface<d>{};
    int first = 0;
    for (std::size_t k = 0; k < entities.size(); ++k) {
      const SurfaceCollision& c = *world.template get<SurfaceCollision>(entities[k]);
      if (const auto* mesh = world.template get<SimplexMesh<d>>(entities[k]))
        dm::addMeshBoundary<d>(surface_, mesh->elements, first, c.thickness, c.friction,
                               c.self ? -1 : static_cast<int>(k));
      if constexpr (d == 3)
        if (const auto* cloth = world.template get<ClothMesh>(entities[k]))
          dm::addFaces<3>(surface_, cloth->triangles, first, particles[k]->count(), c.thickness, c.friction,
                          c.self ? -1 : static_cast<int>(k));
      first += particles[k]->count();
    }
    surface_.thickness.resize(first, 0.0);
    surface_.friction.resize(first, 0.0);
    surface_.group.resize(first, -1);
    bodies_ = bodies;
  }
  std::vector<double> x, v, inverseMass;
  for (const Particles<d>* p : particles) {
    x.insert(x.end(), p->x.begin(), p->x.end());
    v.insert(v.end(), p->v.begin(), p->v.end());
    for (int i = 0; i < p->count(); ++i) inverseMass.push_back(p->fixed[i] ? 0.0 : 1 / p->m[i]);
  }
  const dm::ProximitySettings settings;
  auto& out = ctx.diagnostics;
  if (stage_ == Stage::Collisions) {
    const dm::ProximityReport r = dm::repelProximities<d>(surface_, x, v, inverseMass, ctx.dt, settings);
    out.set("self_collision_repulsions", r.repulsions);
  }
  const dm::ProximityReport c = dm::resolveCollisions<d>(surface_, x, v, inverseMass, ctx.dt, settings);
  out.max("self_collision_impulses", c.collisions);
  out.max("self_collision_passes", c.passes);
  out.max("self_collision_remaining", c.remaining);
  std::size_t offset = 0;
  for (Particles<d>* p : particles) {
    std::copy(v.begin() + offset, v.begin() + offset + p->v.size(), p->v.begin());
    offset += p->v.size();
  }
}

template class DeformableSelfCollision<2>;
template class DeformableSelfCollision<3>;

}  // namespace monolith

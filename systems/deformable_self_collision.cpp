#include "systems/deformable_self_collision.h"

#include "components/cloth.h"
#include "components/collider.h"

namespace monolith {

namespace dm = solvers::deformable;

namespace {

// The rigid bodies that can touch anything and move: with a collider, not static.
template <int d>
std::vector<const RigidBody<d>*> movingColliders(World<d>& world) {
  std::vector<const RigidBody<d>*> out;
  world.template each<RigidBody<d>, Collider<d>>([&](Entity, RigidBody<d>& b, Collider<d>&) {
    if (!b.isStatic) out.push_back(&b);
  });
  return out;
}

}  // namespace

template <int d>
const dm::CollisionSurface<d>& SurfaceCache<d>::get(World<d>& world) {
  std::vector<std::pair<std::uint64_t, int>> bodies;
  world.template each<Particles<d>, SurfaceCollision>([&](Entity e, Particles<d>& p, SurfaceCollision&) {
    bodies.emplace_back((std::uint64_t(e.index) << 32) | e.generation, p.count());
  });
  if (rigidCentres_) bodies.emplace_back(~std::uint64_t(0), static_cast<int>(movingColliders(world).size()));
  if (bodies == bodies_) return surface_;
  bodies_ = bodies;
  surface_ = dm::CollisionSurface<d>{};
  int first = 0, k = 0;
  world.template each<Particles<d>, SurfaceCollision>([&](Entity e, Particles<d>& p, SurfaceCollision& c) {
    const int group = c.self ? -1 : k;
    if (const auto* mesh = world.template get<SimplexMesh<d>>(e))
      dm::addMeshBoundary<d>(surface_, mesh->elements, first, c.thickness, c.friction, group);
    if constexpr (d == 3)
      if (const auto* cloth = world.template get<ClothMesh>(e))
        dm::addFaces<3>(surface_, cloth->triangles, first, p.count(), c.thickness, c.friction, group);
    first += p.count();
    ++k;
  });
  surface_.thickness.resize(first, 0.0);
  surface_.friction.resize(first, 0.0);
  surface_.group.resize(first, -1);
  if (rigidCentres_)
    for (std::size_t k = 0; k < movingColliders(world).size(); ++k) {
      surface_.points.push_back(first++);
      surface_.thickness.push_back(0.0);
      surface_.friction.push_back(0.0);
      surface_.group.push_back(-1);
    }
  return surface_;
}

template <int d>
std::vector<double> SurfaceCache<d>::positions(World<d>& world) const {
  std::vector<double> x;
  world.template each<Particles<d>, SurfaceCollision>(
      [&](Entity, Particles<d>& p, SurfaceCollision&) { x.insert(x.end(), p.x.begin(), p.x.end()); });
  if (rigidCentres_)
    for (const RigidBody<d>* b : movingColliders(world))
      for (int a = 0; a < d; ++a) x.push_back(b->x(a));
  return x;
}

template <int d>
void SurfaceParticles<d>::gather(World<d>& world) {
  pools.clear();
  x.clear();
  v.clear();
  inverseMass.clear();
  world.template each<Particles<d>, SurfaceCollision>([&](Entity, Particles<d>& p, SurfaceCollision&) {
    pools.push_back(&p);
    x.insert(x.end(), p.x.begin(), p.x.end());
    v.insert(v.end(), p.v.begin(), p.v.end());
    for (int i = 0; i < p.count(); ++i) inverseMass.push_back(p.fixed[i] ? 0.0 : 1 / p.m[i]);
  });
}

template <int d>
void SurfaceParticles<d>::scatter(const std::vector<double>& joined, std::vector<double> Particles<d>::*field) const {
  std::size_t offset = 0;
  for (Particles<d>* p : pools) {
    std::vector<double>& out = p->*field;
    std::copy(joined.begin() + offset, joined.begin() + offset + out.size(), out.begin());
    offset += out.size();
  }
}

template <int d>
void DeformableSelfCollision<d>::run(World<d>& world, StepContext& ctx) {
  const dm::CollisionSurface<d>& surface = surfaces_.get(world);
  SurfaceParticles<d> particles(world);
  const std::vector<double>& x = particles.x;
  std::vector<double>& v = particles.v;
  const std::vector<double>& inverseMass = particles.inverseMass;
  if (stage_ == Stage::Contact && v == *afterCollisions_) return;  // Step II's result stands
  const dm::ProximitySettings settings;
  auto& out = ctx.diagnostics;
  if (stage_ == Stage::Collisions) {
    const dm::ProximityReport r = dm::repelProximities<d>(surface, x, v, inverseMass, ctx.dt, settings);
    out.set("self_collision_repulsions", r.repulsions);
  }
  const dm::ProximityReport c = dm::resolveCollisions<d>(surface, x, v, inverseMass, ctx.dt, settings);
  out.max("self_collision_impulses", c.collisions);
  out.max("self_collision_passes", c.passes);
  out.max("self_collision_remaining", c.remaining);
  out.max("self_collision_impact_zones", c.impactZones);
  if (stage_ == Stage::Collisions) *afterCollisions_ = v;
  particles.writeVelocities();
}

template <int d>
void SurfaceCrossings<d>::run(World<d>& world, StepContext& ctx) {
  const dm::CollisionSurface<d>& surface = surfaces_.get(world);
  const std::vector<double> x = surfaces_.positions(world);
  if (stage_ == Stage::ForcesAtStart) {
    scratch_->x = x;
    return;
  }
  if (scratch_->x.size() != x.size()) return;
  // The step's displacement as a velocity over a unit time.
  std::vector<double> displacement(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) displacement[i] = x[i] - scratch_->x[i];
  ctx.diagnostics.max("surface_crossings", dm::countCollisions<d>(surface, scratch_->x, displacement, 1.0));
}

template class SurfaceCache<2>;
template class SurfaceCache<3>;
template struct SurfaceParticles<2>;
template struct SurfaceParticles<3>;
template class DeformableSelfCollision<2>;
template class DeformableSelfCollision<3>;
template class SurfaceCrossings<2>;
template class SurfaceCrossings<3>;

}  // namespace monolith

#include "systems/particle_binding.h"

#include "solvers/deformable/elasticity.h"

namespace monolith {

namespace {

template <int d>
AngularVec<d> armCross(const Vec<d>& r, const Vec<d>& f) {
  if constexpr (d == 3) return r.cross(f);
  else return AngularVec<2>(r.x() * f.y() - r.y() * f.x());
}
template <int d>
Vec<d> angularAt(const AngularVec<d>& w, const Vec<d>& r) {
  if constexpr (d == 3) return w.cross(r);
  else return Vec<2>(-w(0) * r.y(), w(0) * r.x());
}

}  // namespace

template <int d>
std::vector<RigidBody<d>*> boundBodies(World<d>& world, const RigidBinding<d>& b) {
  std::vector<RigidBody<d>*> out;
  for (const auto& name : b.bodyNames()) {
    const auto e = world.find(name);
    out.push_back(e ? world.template get<RigidBody<d>>(*e) : nullptr);
  }
  return out;
}

template <int d>
void BindingForces<d>::run(World<d>& world, StepContext&) {
  world.template each<RigidBinding<d>, Particles<d>, SimplexMesh<d>, Elasticity>(
      [&](Entity e, RigidBinding<d>& b, Particles<d>& p, SimplexMesh<d>& mesh, Elasticity& el) {
        const auto& fm = cache_.get(e, p, mesh, el);
        std::vector<double> f(p.x.size(), 0.0);
        solvers::deformable::addElasticForces<d>(fm, p.x.data(), f.data());
        const auto bodies = boundBodies(world, b);
        for (std::size_t k = 0; k < b.particle.size(); ++k) {
          RigidBody<d>* body = bodies[b.body[k]];
          if (!body || body->isStatic) continue;
          const auto bodyEntity = world.find(b.bodyNames()[b.body[k]]);
          RigidForces<d>* acc = world.template get<RigidForces<d>>(*bodyEntity);
          if (!acc) continue;
          const int i = b.particle[k];
          const Vec<d> fi = Eigen::Map<const Vec<d>>(&f[d * i]);
          const Vec<d> r = Eigen::Map<const Vec<d>>(&p.x[d * i]) - body->x;
          acc->force += fi;
          acc->torque += armCross<d>(r, fi);
        }
      });
}

template <int d>
void followBoundBodies(World<d>& world, bool positions) {
  world.template each<RigidBinding<d>, Particles<d>>([&](Entity, RigidBinding<d>& b, Particles<d>& p) {
    const auto bodies = boundBodies(world, b);
    for (std::size_t k = 0; k < b.particle.size(); ++k) {
      const RigidBody<d>* body = bodies[b.body[k]];
      if (!body) continue;
      const int i = b.particle[k];
      const Vec<d> r = body->rotation() * Vec<d>(Eigen::Map<const Vec<d>>(&b.offset[d * k]));
      Eigen::Map<Vec<d>> x(&p.x[d * i]), v(&p.v[d * i]);
      if (positions) x = body->x + r;
      v = body->isStatic ? Vec<d>::Zero() : Vec<d>(body->v + angularAt<d>(body->omega(), r));
    }
  });
}

template <int d>
void FollowBoundBodies<d>::run(World<d>& world, StepContext&) {
  followBoundBodies(world, stage_ == Stage::AdvancePositions);
}

template std::vector<RigidBody<2>*> boundBodies<2>(World<2>&, const RigidBinding<2>&);
template std::vector<RigidBody<3>*> boundBodies<3>(World<3>&, const RigidBinding<3>&);
template void followBoundBodies<2>(World<2>&, bool);
template void followBoundBodies<3>(World<3>&, bool);
template class BindingForces<2>;
template class BindingForces<3>;
template class FollowBoundBodies<2>;
template class FollowBoundBodies<3>;

}  // namespace monolith

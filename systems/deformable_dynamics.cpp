#include "systems/deformable_dynamics.h"

#include <algorithm>
#include <cmath>

#include "components/cloth.h"
#include "components/fluid_coupling.h"
#include "components/forces.h"
#include "components/sleep.h"
#include "systems/embedded_binding.h"
#include "systems/particle_contact.h"

#include "solvers/deformable/coupled_damping.h"
#include "solvers/deformable/simplex_mesh.h"
#include "solvers/deformable/stable_step.h"

namespace monolith {

namespace dm = solvers::deformable;

template <int d>
dm::ForceModel<d> forceModelOf(const Particles<d>& p, const SimplexMesh<d>& mesh, const Elasticity& e) {
  dm::Material mat;
  mat.model = static_cast<dm::Model>(e.model);
  mat.density = e.density;
  mat.youngsModulus = e.youngsModulus;
  mat.poissonRatio = e.poissonRatio;
  mat.rayleighAlpha = e.rayleighAlpha;
  mat.rayleighBeta = e.rayleighBeta;
  mat.overdamping = e.overdamping;
  mat.altitudeStiffness = e.altitudeStiffness;
  mat.clamp = e.clamp;
  // The state's masses are authoritative (also for the springs' critical damping).
  dm::ForceModel<d> fm = dm::prepareForceModel<d>(mesh.restX, mesh.elements, mat, p.m);
  return fm;
}

template <int d>
const dm::ForceModel<d>& ForceModelCache<d>::get(Entity e, const Particles<d>& p, const SimplexMesh<d>& m,
                                                 const Elasticity& el) {
  const std::uint64_t key = (std::uint64_t(e.index) << 32) | e.generation;
  auto it = models_.find(key);
  if (it == models_.end()) it = models_.emplace(key, forceModelOf(p, m, el)).first;
  return it->second;
}

template <int d>
std::vector<double> explicitForces(const dm::ForceModel<d>& fm, const Particles<d>& p, const Vec<d>& gravity,
                                   std::vector<dm::MatD<d>>* rotations) {
  std::vector<double> f(p.x.size(), 0.0);
  dm::addElasticForces<d>(fm, p.x.data(), f.data(), rotations);
  for (int i = 0; i < p.count(); ++i)
    for (int a = 0; a < d; ++a)
      // An embedded particle keeps its elastic force (its hosts take it); its weight is theirs.
      f[d * i + a] = p.fixed[i] == 3 ? f[d * i + a] : p.fixed[i] ? 0.0 : f[d * i + a] + p.m[i] * gravity(a);
  return f;
}

template <int d>
ImplicitSolveReport implicitDampingSolve(const dm::ForceModel<d>& fm, const Particles<d>& p,
                                         const std::vector<double>& f, double h, std::vector<double>& u,
                                         std::vector<double>* dampingForce,
                                         const std::vector<dm::MatD<d>>* rotations,
                                         const std::vector<NormalConstraint<d>>* normals) {
  const std::vector<dm::MatD<d>> computed =
      rotations || fm.dampingRows() == 0 ? std::vector<dm::MatD<d>>() : dm::dampingRotations<d>(fm, p.x.data());
  dm::DampingBody<d> body;
  body.fm = &fm;
  body.rotations = rotations ? rotations : &computed;
  body.x = p.x.data();
  body.v = p.v.data();
  body.m = p.m.data();
  body.f = f.data();
  body.role.resize(p.count());
  body.rigid.assign(p.count(), -1);
  for (int i = 0; i < p.count(); ++i) body.role[i] = p.fixed[i] ? dm::ParticleRole::Prescribed : dm::ParticleRole::Free;
  std::vector<dm::DampingHold<d>> holds;
  if (normals)
    for (const NormalConstraint<d>& c : *normals) {
      if (c.rigid.valid())
        throw std::invalid_argument("implicitDampingSolve: a hold against a dynamic rigid body needs the coupled solve");
      holds.push_back({0, c.particle, c.normal, c.velocity, -1});
    }
  dm::CoupledDampingResult<d> r = dm::solveCoupledDamping<d>({std::move(body)}, {}, std::move(holds), h);
  u = std::move(r.u[0]);
  if (dampingForce) *dampingForce = std::move(r.Du[0]);
  ImplicitSolveReport report;
  report.iterations = r.report.iterations;
  report.relativeResidual = r.report.relativeResidual;
  report.converged = r.report.converged;
  return report;
}

namespace {

// Disjoint sets over the bodies of a stage (bodies tied through a rigid unknown are solved together).
int findRoot(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

template <int d>
AdvanceDeformableVelocity<d>::AdvanceDeformableVelocity(Stage s)
    : stage_(s), contacts_(std::make_unique<DampingSolveContacts<d>>()) {}

template <int d>
AdvanceDeformableVelocity<d>::~AdvanceDeformableVelocity() = default;

template <int d>
void AdvanceDeformableVelocity<d>::run(World<d>& world, StepContext& ctx) {
  const bool half = stage_ == Stage::AdvanceVelocityHalf;
  const Vec<d> g = world.settings().gravity;
  const double h = half ? 0.5 * ctx.dt : 0.25 * ctx.dt;
  int iterations = 0;
  // The explicit forces of every body first: an embedded particle's elastic force joins its host's
  // before the host's solve, whichever comes first in pool order.
  struct Body {
    Entity e;
    Particles<d>* p;
    const dm::ForceModel<d>* fm;
    std::vector<dm::MatD<d>> R;
    std::vector<double> f, Du;
  };
  std::vector<Body> bodies;
  world.template each<Particles<d>, SimplexMesh<d>, Elasticity>(
      [&](Entity e, Particles<d>& p, SimplexMesh<d>& mesh, Elasticity& el) {
        // A body coupled to a fluid takes its velocity steps in the coupled solve, its damping
        // inside it (systems/fluid_structure_coupling.h).
        if (world.template has<FluidCoupling<d>>(e)) return;
        Body b{e, &p, &cache_.get(e, p, mesh, el), {}, {}, {}};
        b.f = explicitForces(*b.fm, p, g, &b.R);
        bodies.push_back(std::move(b));
      });
  auto bodyOf = [&](Entity e) -> Body* {
    for (Body& b : bodies)
      if (b.e == e) return &b;
    return nullptr;
  };
  const bool embedding = world.template count<EmbeddedBinding<d>>() > 0;
  if (embedding)
    for (Body& b : bodies)
      if (const EmbeddedBinding<d>* eb = world.template get<EmbeddedBinding<d>>(b.e))
        forEachHostWeight<d>(world, *eb, [&](Entity host, int j, double w, int i) {
          if (Body* hb = bodyOf(host))
            for (int a = 0; a < d; ++a) hb->f[d * j + a] += w * b.f[d * i + a];
        });
  // The dynamic rigid bodies tied to a damped body, by a binding or a held contact, are unknowns
  // of its solve (Sec. 4.7.3); bodies sharing one are solved together. Rigid unknowns are
  // numbered in order of first use (bodies in pool order, bindings, then holds in particle
  // order), so the order is the same on any thread count.
  struct Rigid {
    Entity e;
    RigidBody<d>* body;
  };
  std::vector<Rigid> rigids;
  auto rigidIndex = [&](Entity e, RigidBody<d>* body) {
    for (std::size_t k = 0; k < rigids.size(); ++k)
      if (rigids[k].e == e) return static_cast<int>(k);
    rigids.push_back({e, body});
    return static_cast<int>(rigids.size()) - 1;
  };
  auto dynamicBody = [&](Entity e) -> RigidBody<d>* {
    RigidBody<d>* body = world.template get<RigidBody<d>>(e);
    return body && !body->isStatic && !world.template has<KinematicMotion<d>>(e) ? body : nullptr;
  };
  const int bodyCount = static_cast<int>(bodies.size());
  std::vector<std::vector<dm::ParticleRole>> roles(bodyCount);
  std::vector<std::vector<int>> boundTo(bodyCount);
  std::vector<std::vector<NormalConstraint<d>>> held(bodyCount);
  std::vector<std::vector<int>> heldRigid(bodyCount);
  std::vector<int> parent(bodyCount);
  std::vector<std::pair<int, int>> uses;  // (deformable body, rigid unknown)
  std::vector<std::vector<dm::EmbeddedWeight>> embeddedIn(bodyCount);  // hostBody: index into bodies
  for (int k = 0; k < bodyCount; ++k) {
    parent[k] = k;
    const Body& b = bodies[k];
    const Particles<d>& p = *b.p;
    roles[k].resize(p.count());
    boundTo[k].assign(p.count(), -1);
    for (int i = 0; i < p.count(); ++i) roles[k][i] = p.fixed[i] ? dm::ParticleRole::Prescribed : dm::ParticleRole::Free;
    if (b.fm->dampingRows() == 0) continue;  // no damping: the solve is M u = M v + h f, nothing couples
    std::vector<int> used;
    if (const RigidBinding<d>* binding = world.template get<RigidBinding<d>>(b.e)) {
      const auto names = binding->bodyNames();
      std::vector<int> index(names.size(), -1);
      for (std::size_t j = 0; j < names.size(); ++j)
        if (const auto e = world.find(names[j]))
          if (RigidBody<d>* body = dynamicBody(*e)) index[j] = rigidIndex(*e, body);
      for (std::size_t j = 0; j < binding->particle.size(); ++j) {
        const int c = index[binding->body[j]];
        if (c < 0) continue;  // static or kinematic: the particle's velocity is prescribed
        roles[k][binding->particle[j]] = dm::ParticleRole::Bound;
        boundTo[k][binding->particle[j]] = c;
        used.push_back(c);
      }
    }
    // Embedded particles follow their host element inside the solve (their velocity the weighted
    // host velocities), the host body solved together with this one.
    if (embedding)
      if (const EmbeddedBinding<d>* eb = world.template get<EmbeddedBinding<d>>(b.e))
        forEachHostWeight<d>(world, *eb, [&](Entity host, int j, double w, int i) {
          const Body* hb = bodyOf(host);
          if (!hb || hb == &b) return;  // host coupled to a fluid: prescribed, its force handed over after
          roles[k][i] = dm::ParticleRole::Embedded;
          embeddedIn[k].push_back({i, static_cast<int>(hb - bodies.data()), j, w});
        });
    if (contacts_) held[k] = contacts_->of(world, p, ctx.dt, half ? 0.0 : 0.5);
    for (const NormalConstraint<d>& c : held[k]) {
      int index = -1;
      if (c.rigid.valid()) {
        index = rigidIndex(c.rigid, world.template get<RigidBody<d>>(c.rigid));
        used.push_back(index);
      }
      heldRigid[k].push_back(index);
    }
    for (int c : used) uses.push_back({k, c});
  }
  // The rigid unknowns' own contacts and joints (rows on their twists); dynamic bodies they reach
  // join the unknowns.
  std::vector<dm::DampingRigidRow<d>> allRows;
  if (!rigids.empty()) {
    std::vector<Entity> unknowns;
    for (const Rigid& r : rigids) unknowns.push_back(r.e);
    const std::vector<RigidConstraintRow<d>> found = contacts_->rigidRows(world, unknowns, ctx.dt, half ? 0.0 : 0.5);
    for (std::size_t k = rigids.size(); k < unknowns.size(); ++k)
      rigidIndex(unknowns[k], world.template get<RigidBody<d>>(unknowns[k]));
    for (const RigidConstraintRow<d>& r : found) {
      dm::DampingRigidRow<d> row;
      row.a = rigidIndex(r.a, nullptr);
      row.b = r.b.valid() ? rigidIndex(r.b, nullptr) : -1;
      row.ga = r.ga;
      row.gb = r.gb;
      row.target = r.target;
      allRows.push_back(row);
    }
  }
  // Disjoint sets over the deformable bodies (nodes 0 .. bodyCount - 1) and the rigid unknowns
  // (after them): a body with the rigid unknowns it uses, two unknowns sharing a row.
  parent.resize(bodyCount + rigids.size());
  for (std::size_t k = bodyCount; k < parent.size(); ++k) parent[k] = static_cast<int>(k);
  auto unite = [&](int a, int b) {
    a = findRoot(parent, a);
    b = findRoot(parent, b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);  // the smallest node is the root
  };
  for (const auto& [k, c] : uses) unite(k, bodyCount + c);
  for (int k = 0; k < bodyCount; ++k)
    for (const dm::EmbeddedWeight& e : embeddedIn[k]) unite(k, e.hostBody);
  for (const dm::DampingRigidRow<d>& r : allRows)
    if (r.b >= 0) unite(bodyCount + r.a, bodyCount + r.b);
  // The rigid unknowns' twists at the start of the solve. Step I: v^{n+1/2} after the rigid
  // half kick. Step V solves for the average of v^{n+1/2} and v^{n+1} (backward Euler over dt/4,
  // then extrapolation), so the body's own kick over dt/4 is taken off again, as its particles'
  // explicit forces enter over dt/4.
  const auto* sleeps = world.template findPool<Sleep<d>>();
  std::vector<dm::DampingRigid<d>> rigidStart(rigids.size());
  for (std::size_t c = 0; c < rigids.size(); ++c) {
    const RigidBody<d>& body = *rigids[c].body;
    Vec<d> v = body.v;
    AngularVec<d> L = body.L;
    if (!half)
      if (const RigidForces<d>* force = world.template get<RigidForces<d>>(rigids[c].e);
          force && !isAsleep<d>(sleeps, rigids[c].e)) {
        v -= (0.25 * ctx.dt / body.mass) * force->force;
        L -= 0.25 * ctx.dt * force->torque;
      }
    rigidStart[c].mass = body.mass;
    rigidStart[c].inertia = body.worldInertia();
    rigidStart[c].x = body.x;
    rigidStart[c].v = v;
    rigidStart[c].omega = body.worldInverseInertia() * L;
  }
  for (int root = 0; root < bodyCount; ++root) {
    if (findRoot(parent, root) != root) continue;
    std::vector<int> members;  // ascending: the root is the smallest
    for (int k = root; k < bodyCount; ++k)
      if (findRoot(parent, k) == root) members.push_back(k);
    std::vector<int> local(rigids.size(), -1), global;
    auto localRigid = [&](int c) {
      if (local[c] < 0) {
        local[c] = static_cast<int>(global.size());
        global.push_back(c);
      }
      return local[c];
    };
    std::vector<dm::DampingBody<d>> solveBodies;
    std::vector<dm::DampingHold<d>> holds;
    for (std::size_t m = 0; m < members.size(); ++m) {
      Body& b = bodies[members[m]];
      dm::DampingBody<d> sb;
      sb.fm = b.fm;
      sb.rotations = &b.R;
      sb.x = b.p->x.data();
      sb.v = b.p->v.data();
      sb.m = b.p->m.data();
      sb.f = b.f.data();
      sb.role = roles[members[m]];
      sb.rigid = boundTo[members[m]];
      for (int& c : sb.rigid)
        if (c >= 0) c = localRigid(c);
      sb.embedded = embeddedIn[members[m]];
      for (dm::EmbeddedWeight& e : sb.embedded)
        e.hostBody = static_cast<int>(std::find(members.begin(), members.end(), e.hostBody) - members.begin());
      const auto& bodyHeld = held[members[m]];
      for (std::size_t j = 0; j < bodyHeld.size(); ++j) {
        const int c = heldRigid[members[m]][j];
        holds.push_back({static_cast<int>(m), bodyHeld[j].particle, bodyHeld[j].normal, bodyHeld[j].velocity,
                         c >= 0 ? localRigid(c) : -1});
      }
      solveBodies.push_back(std::move(sb));
    }
    std::vector<dm::DampingRigidRow<d>> rows;
    for (const dm::DampingRigidRow<d>& row : allRows)
      if (findRoot(parent, bodyCount + row.a) == root) {
        dm::DampingRigidRow<d> local = row;
        local.a = localRigid(row.a);
        if (row.b >= 0) local.b = localRigid(row.b);
        rows.push_back(local);
      }
    std::vector<dm::DampingRigid<d>> solveRigids;
    for (int c : global) solveRigids.push_back(rigidStart[c]);
    dm::CoupledDampingResult<d> r =
        dm::solveCoupledDamping<d>(std::move(solveBodies), std::move(solveRigids), std::move(holds), h, std::move(rows));
    iterations = std::max(iterations, r.report.iterations);
    for (std::size_t m = 0; m < members.size(); ++m) {
      Body& b = bodies[members[m]];
      Particles<d>& p = *b.p;
      const std::vector<double>& u = r.u[m];
      if (half) p.v = u;
      else
        for (std::size_t i = 0; i < u.size(); ++i) p.v[i] = 2 * u[i] - p.v[i];
      b.Du = std::move(r.Du[m]);
    }
    // The damping forces on the bound particles act on their bodies over this stage's velocity
    // change: h (Step I) or 2h (Step V's extrapolation).
    const double duration = half ? h : 2 * h;
    for (std::size_t c = 0; c < global.size(); ++c) {
      RigidBody<d>& body = *rigids[global[c]].body;
      body.v += (duration / body.mass) * r.force[c];
      body.L += duration * r.torque[c];
    }
  }
  // The damping forces on embedded particles whose host was not in their solve (a host coupled to
  // a fluid), over the same duration, to their hosts' particles in their weights (after every
  // solve of the stage). In the solve, an embedded particle's force is already its hosts' and its
  // own entry of Du is zero.
  if (embedding)
    for (Body& b : bodies)
      if (const EmbeddedBinding<d>* eb = world.template get<EmbeddedBinding<d>>(b.e); eb && !b.Du.empty())
        forEachHostWeight<d>(world, *eb, [&](Entity host, int j, double w, int i) {
          Particles<d>& hp = *world.template get<Particles<d>>(host);
          if (hp.fixed[j]) return;
          for (int a = 0; a < d; ++a) hp.v[d * j + a] += (half ? h : 2 * h) * w * b.Du[d * i + a] / hp.m[j];
        });
  // Free particles without a mesh (single mass points) feel gravity only: both stages add
  // dt/2 g (Step V's backward Euler over dt/4 plus extrapolation doubles its dt/4).
  world.template each<Particles<d>>([&](Entity e, Particles<d>& p) {
    if (world.template has<SimplexMesh<d>>(e) || world.template has<ClothMesh>(e)) return;  // cloth: its own systems
    for (int i = 0; i < p.count(); ++i)
      if (!p.fixed[i])
        for (int a = 0; a < d; ++a) p.v[d * i + a] += 0.5 * ctx.dt * g(a);
  });
  ctx.diagnostics.max(half ? "deformable_cg_iterations_half" : "deformable_cg_iterations", iterations);
  // Without a tetrahedral or triangle solid (cloth only) there is no elastic limit: the
  // stable step is infinite and not reported, since the run's guard refuses non-finite values.
  if (half) {
    const double stableDt = unitCflDt(world);
    if (std::isfinite(stableDt)) ctx.diagnostics.set("deformable_stable_dt", stableDt);
  }
}

template <int d>
double AdvanceDeformableVelocity<d>::unitCflDt(const World<d>& world) const {
  double dt = std::numeric_limits<double>::infinity();
  if (stage_ != Stage::AdvanceVelocityHalf) return dt;  // one of the two stages reports it
  const auto* pool = world.template findPool<Particles<d>>();
  if (!pool) return dt;
  for (std::size_t k = 0; k < pool->size(); ++k) {
    const Entity e = pool->entities()[k];
    const Particles<d>& p = pool->components()[k];
    const auto* mesh = world.template get<SimplexMesh<d>>(e);
    const auto* el = world.template get<Elasticity>(e);
    if (!mesh || !el) continue;
    const auto& fm = cache_.get(e, p, *mesh, *el);
    dt = std::min(dt, dm::stableStep<d>(fm, el->density, p.x.data(), p.v.data(), p.fixed).value());
  }
  return dt;
}

template <int d>
void AdvanceDeformablePositions<d>::run(World<d>& world, StepContext& ctx) {
  world.template each<Particles<d>>([&](Entity, Particles<d>& p) {
    for (int i = 0; i < p.count(); ++i)
      if (!p.fixed[i])
        for (int a = 0; a < d; ++a) p.x[d * i + a] += ctx.dt * p.v[d * i + a];
  });
}

template <int d>
DeformableTotals measureDeformableTotals(const World<d>& world, ForceModelCache<d>* cache) {
  DeformableTotals t;
  const auto* pool = world.template findPool<Particles<d>>();
  if (!pool) return t;
  const Vec<d> g = world.settings().gravity;
  for (std::size_t k = 0; k < pool->size(); ++k) {
    const Entity e = pool->entities()[k];
    const Particles<d>& p = pool->components()[k];
    for (int i = 0; i < p.count(); ++i) {
      if (p.fixed[i] >= 2) continue;  // bound or embedded: its mass is part of its body's or host's
      const Eigen::Map<const Vec<d>> x(&p.x[d * i]), v(&p.v[d * i]);
      t.kinetic += 0.5 * p.m[i] * v.squaredNorm();
      if (p.fixed[i] == 0) t.potential -= p.m[i] * g.dot(x);
      Eigen::Vector3d x3 = Eigen::Vector3d::Zero(), p3 = Eigen::Vector3d::Zero();
      x3.template head<d>() = x;
      p3.template head<d>() = p.m[i] * v;
      t.linearMomentum += p3;
      t.angularMomentum += x3.cross(p3);
    }
    const auto* mesh = world.template get<SimplexMesh<d>>(e);
    const auto* el = world.template get<Elasticity>(e);
    if (mesh && el)
      t.elastic += cache ? dm::elasticEnergy<d>(cache->get(e, p, *mesh, *el), p.x.data())
                         : dm::elasticEnergy<d>(forceModelOf(p, *mesh, *el), p.x.data());
  }
  return t;
}

template <int d>
void DeformableDiagnostics<d>::run(World<d>& world, StepContext& ctx) {
  const DeformableTotals t = measureDeformableTotals(world, &cache_);
  auto& out = ctx.diagnostics;
  out.add("kinetic_energy", t.kinetic);
  out.add("potential_energy", t.potential + t.elastic);
  out.add("total_energy", t.kinetic + t.potential + t.elastic);
  out.set("deformable_elastic_energy", t.elastic);
  out.add("linear_momentum_x", t.linearMomentum.x());
  out.add("linear_momentum_y", t.linearMomentum.y());
  out.add("linear_momentum_z", t.linearMomentum.z());
  out.add("angular_momentum_x", t.angularMomentum.x());
  out.add("angular_momentum_y", t.angularMomentum.y());
  out.add("angular_momentum_z", t.angularMomentum.z());
}

#define MONOLITH_INSTANTIATE(D)                                                                                 \
  template dm::ForceModel<D> forceModelOf<D>(const Particles<D>&, const SimplexMesh<D>&, const Elasticity&);   \
  template class ForceModelCache<D>;                                                                            \
  template std::vector<double> explicitForces<D>(const dm::ForceModel<D>&, const Particles<D>&, const Vec<D>&,  \
                                                 std::vector<dm::MatD<D>>*);                                    \
  template ImplicitSolveReport implicitDampingSolve<D>(const dm::ForceModel<D>&, const Particles<D>&,          \
                                                       const std::vector<double>&, double, std::vector<double>&, \
                                                       std::vector<double>*, const std::vector<dm::MatD<D>>*,    \
                                                       const std::vector<NormalConstraint<D>>*);                \
  template class AdvanceDeformableVelocity<D>;                                                                  \
  template class AdvanceDeformablePositions<D>;                                                                 \
  template class DeformableDiagnostics<D>;                                                                      \
  template DeformableTotals measureDeformableTotals<D>(const World<D>&, ForceModelCache<D>*);
MONOLITH_INSTANTIATE(2)
MONOLITH_INSTANTIATE(3)
#undef MONOLITH_INSTANTIATE

}  // namespace monolith

#include "systems/deformable_dynamics.h"

#include <cmath>

#include "components/cloth.h"
#include "components/fluid_coupling.h"
#include "systems/embedded_binding.h"
#include "systems/particle_contact.h"

#include "solvers/deformable/simplex_mesh.h"
#include "solvers/deformable/stable_step.h"
#include "solvers/fluid/krylov.h"

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
  const int n = static_cast<int>(p.x.size());
  ImplicitSolveReport report;
  u.assign(n, 0.0);
  auto constrained = [&](int i) { return p.fixed[i / d] != 0; };
  if (fm.dampingRows() == 0) {  // no damping: M u = M v + h f directly
    for (int i = 0; i < n; ++i) u[i] = constrained(i) ? p.v[i] : p.v[i] + h * f[i] / p.m[i / d];
    if (dampingForce) dampingForce->assign(n, 0.0);
    return report;
  }
  const std::vector<dm::MatD<d>> computed = rotations ? std::vector<dm::MatD<d>>() : dm::dampingRotations<d>(fm, p.x.data());
  const std::vector<dm::MatD<d>>& R = rotations ? *rotations : computed;
  Eigen::VectorXd diag(n), prescribed = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) {
    diag(i) = p.m[i / d];
    if (constrained(i)) prescribed(i) = p.v[i];  // fixed: 0; bound: the body's point velocity
  }
  const solvers::LinearOperator A = [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) {
    std::vector<double> Dv(n, 0.0);
    dm::addDampingForces<d>(fm, R, p.x.data(), in.data(), Dv.data());
    for (int i = 0; i < n; ++i) out(i) = diag(i) * in(i) - h * Dv[i];
  };
  // Constrained components are prescribed: u = w + prescribed with w zero on them, and
  // P A P w = P (b - A prescribed), P zeroing the constrained components. P is symmetric, so
  // P A P stays SPD on the free subspace (Sec. 4.7.3 with the constraint rows of the fixed and
  // bound particles).
  std::vector<NormalConstraint<d>> held;
  if (normals)
    for (const NormalConstraint<d>& c : *normals)
      if (!p.fixed[c.particle]) {
        held.push_back(c);
        for (int a = 0; a < d; ++a) prescribed(d * c.particle + a) = c.velocity * c.normal(a);
      }
  const solvers::Projector project = [&](Eigen::VectorXd& v) {
    for (int i = 0; i < n; ++i)
      if (constrained(i)) v(i) = 0;
    for (const NormalConstraint<d>& c : held) {
      Eigen::Map<Vec<d>> vi(v.data() + d * c.particle);
      vi -= vi.dot(c.normal) * c.normal;
    }
  };
  Eigen::VectorXd b(n), Ap(n), x(n);
  A(prescribed, Ap);
  for (int i = 0; i < n; ++i) {
    b(i) = p.m[i / d] * p.v[i] + h * f[i] - Ap(i);
    x(i) = p.v[i];
  }
  solvers::CgSettings settings;
  settings.relativeTolerance = 1e-10;
  settings.maxIterations = 2000;
  project(x);
  // CG runs on P A P itself: the product is projected too, so the recursive residual stays in
  // the free subspace and the stopping test measures the residual of the projected system ("can
  // be solved with conjugate gradient provided the residual is properly projected at each
  // iteration", Sec. 4.7.3). Projecting only the preconditioned residual (enough for a null-space
  // projector, which A p never leaves) would leave in r the constrained components of A p: the
  // forces that hold the fixed, bound and contact particles, which do not vanish at the
  // solution. The test would never pass, and CG would run on past convergence on round-off until
  // it broke down by chance, or diverge: drop_sphere_elastic at t = 1.4376 s (a ball resting on six
  // held contacts) then takes 2000 iterations in Step I to a residual of 1e50 and blows up.
  const solvers::LinearOperator projectedA = [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) {
    A(in, out);
    project(out);
  };
  const solvers::CgReport r =
      solvers::conjugateGradient(projectedA, solvers::jacobiPreconditioner(diag), project, b, x, settings);
  report.iterations = r.iterations;
  report.relativeResidual = r.relativeResidual();
  report.converged = r.converged;
  for (int i = 0; i < n; ++i) u[i] = x(i) + prescribed(i);
  std::vector<double> Du(n, 0.0);
  dm::addDampingForces<d>(fm, R, p.x.data(), u.data(), Du.data());
  // The velocity is taken from the forces at the solution, unprojected (Sec. 4.7.2, step 3: a
  // rather than the projected a-hat): held particles get back their constraint's share, and the
  // total momentum changes by exactly h sum f (the damping forces are internal; on bound particles
  // they go to the bodies), not by the solver's residual, which CG leaves at its tolerance.
  for (int i = 0; i < n; ++i)
    if (!constrained(i)) u[i] = p.v[i] + h * (f[i] + Du[i]) / p.m[i / d];
  if (dampingForce) *dampingForce = std::move(Du);
  return report;
}

namespace {

template <int d>
AngularVec<d> armCross(const Vec<d>& r, const Vec<d>& f) {
  if constexpr (d == 3) return r.cross(f);
  else return AngularVec<2>(r.x() * f.y() - r.y() * f.x());
}

template <int d>
void applyBoundDamping(World<d>& world, const RigidBinding<d>& b, const Particles<d>& p, const std::vector<double>& Du,
                       double duration) {
  const auto names = b.bodyNames();
  std::vector<RigidBody<d>*> bodies;
  for (const auto& name : names) {
    const auto e = world.find(name);
    bodies.push_back(e ? world.template get<RigidBody<d>>(*e) : nullptr);
  }
  for (std::size_t k = 0; k < b.particle.size(); ++k) {
    RigidBody<d>* body = bodies[b.body[k]];
    if (!body || body->isStatic) continue;
    const int i = b.particle[k];
    const Vec<d> j = duration * Vec<d>(Eigen::Map<const Vec<d>>(&Du[d * i]));
    body->v += j / body->mass;
    body->L += armCross<d>(Vec<d>(Eigen::Map<const Vec<d>>(&p.x[d * i]) - body->x), j);
  }
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
  for (Body& b : bodies) {
    Particles<d>& p = *b.p;
    std::vector<double> u;
    RigidBinding<d>* binding = world.template get<RigidBinding<d>>(b.e);
    const bool embedded = embedding && world.template has<EmbeddedBinding<d>>(b.e);
    std::vector<NormalConstraint<d>> held;
    if (contacts_ && b.fm->dampingRows() > 0) held = contacts_->of(world, p, ctx.dt, half ? 0.0 : 0.5);
    const ImplicitSolveReport r =
        implicitDampingSolve(*b.fm, p, b.f, h, u, binding || embedded ? &b.Du : nullptr, &b.R, &held);
    iterations = std::max(iterations, r.iterations);
    // The damping forces the solve put on bound particles act on their bodies: over this
    // stage's velocity change, h (Step I) or 2h (Step V's extrapolation) times D u.
    if (binding) applyBoundDamping(world, *binding, p, b.Du, half ? h : 2 * h);
    if (half) p.v = u;
    else
      for (std::size_t i = 0; i < u.size(); ++i) p.v[i] = 2 * u[i] - p.v[i];
  }
  // The damping forces on embedded particles, over the same duration, to their hosts' particles
  // in their weights (after every solve of the stage, as the bound particles' to their bodies).
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

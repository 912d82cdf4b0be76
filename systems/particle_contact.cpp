#include "systems/particle_contact.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "solvers/collision/collision_impl.h"
#include "solvers/collision/narrow_phase.h"
#include "solvers/contact/central_normal_contact.h"
#include "solvers/contact/push_out.h"
#include "systems/contact_workspace.h"
#include "systems/joint_assembly.h"

namespace monolith {

namespace col = solvers::collision;
namespace cc = solvers::contact;

namespace {

constexpr int kContactSweeps = 4;
// Mass of a static or kinematic support in the central-body solve, relative to the body and
// its particles: large enough that the support's constraint holds to about 1e-8 relative, small
// enough that the 6x6 system stays well conditioned in double precision.
constexpr double kSupportMassRatio = 1e8;
constexpr double kSupportMargin = 0.01;

template <int d>
using MatD = Eigen::Matrix<double, d, d>;

// r x j as the body's angular quantity (a number about z in 2-D).
template <int d>
AngularVec<d> crossArm(const Vec<d>& r, const Vec<d>& j) {
  if constexpr (d == 3) return r.cross(j);
  else return AngularVec<2>(r.x() * j.y() - r.y() * j.x());
}
// w x r.
template <int d>
Vec<d> angularAt(const AngularVec<d>& w, const Vec<d>& r) {
  if constexpr (d == 3) return w.cross(r);
  else return Vec<2>(-w(0) * r.y(), w(0) * r.x());
}

// One rigid body as the contact sees it: pose (candidate or current), inverse mass and
// world inverse inertia (zero for static and kinematic bodies), friction.
template <int d>
struct BodyView {
  RigidBody<d>* body = nullptr;
  Entity entity;
  const col::PreparedGeometry<d>* geometry = nullptr;
  Vec<d> x;
  MatD<d> R;
  double inverseMass = 0;
  InertiaMat<d> inverseInertia = InertiaMat<d>::Zero();
  double friction = 0;
  bool infinite = false;  // static or kinematic
};

template <int d>
MatD<d> candidateRotation(const RigidBody<d>& b, double dt) {
  if constexpr (d == 3) {
    const Eigen::Vector3d w = b.omega();
    const double angle = dt * w.norm();
    if (angle == 0) return b.rotation();
    return Eigen::AngleAxisd(angle, w.normalized()).toRotationMatrix() * b.rotation();
  } else {
    return Eigen::Rotation2Dd(b.orientation + dt * b.omega()(0)).toRotationMatrix();
  }
}

template <int d>
std::vector<BodyView<d>> bodiesOf(World<d>& world, PreparedShapes<d>& shapes, double candidateDt, bool twoWay) {
  std::vector<BodyView<d>> out;
  world.template each<RigidBody<d>, Shape<d>, Collider<d>>([&](Entity e, RigidBody<d>& b, Shape<d>& s, Collider<d>& c) {
    BodyView<d> v;
    v.body = &b;
    v.entity = e;
    v.geometry = &shapes.get(e, s);
    const bool infinite = b.isStatic || world.template has<KinematicMotion<d>>(e);
    v.x = b.x + candidateDt * (b.isStatic ? Vec<d>::Zero() : b.v);
    v.R = b.isStatic || candidateDt == 0 ? b.rotation() : candidateRotation(b, candidateDt);
    v.infinite = infinite;
    if (!infinite && twoWay) {
      v.inverseMass = 1 / b.mass;
      v.inverseInertia = b.worldInverseInertia();
    }
    v.friction = c.friction;
    out.push_back(v);
  });
  return out;
}

// Signed distance of world point q to the posed body, with the world normal; false when the
// point is clearly farther than `limit`.
template <int d>
bool distanceTo(const BodyView<d>& b, const Vec<d>& q, double limit, double& distance, Vec<d>& normal) {
  if (!b.geometry->unbounded() && (q - b.x).norm() > b.geometry->boundingRadius() + limit) return false;
  const col::SurfaceDistance<d> s = col::signedDistance<d>(*b.geometry, b.R.transpose() * (q - b.x), limit);
  if (!(s.distance < limit)) return false;
  distance = s.distance;
  normal = b.R * s.normal;
  return true;
}

// Velocity change of the body's point at arm r per impulse j applied to it.
template <int d>
Vec<d> bodyResponse(const BodyView<d>& b, const Vec<d>& r, const Vec<d>& j) {
  return b.inverseMass * j + angularAt<d>(AngularVec<d>(b.inverseInertia * crossArm<d>(r, j)), r);
}

// The tangential impulse on the particle (minus on the body) that stops the relative sliding u_t
// at the contact, on the Coulomb disc of radius `limit` (mu times the contact's normal impulse).
template <int d>
Vec<d> frictionImpulse(const BodyView<d>& b, double particleMass, const Vec<d>& r, const Vec<d>& u, const Vec<d>& n,
                       double limit) {
  const Vec<d> ut = u - u.dot(n) * n;
  if (ut.squaredNorm() == 0 || limit <= 0) return Vec<d>::Zero();
  MatD<d> K;  // relative velocity change per unit impulse on the particle
  for (int k = 0; k < d; ++k) {
    const Vec<d> e = Vec<d>::Unit(k);
    K.col(k) = e / particleMass + bodyResponse(b, r, e);
  }
  Vec<d> j = K.lu().solve(-ut);
  j -= j.dot(n) * n;
  const double size = j.norm();
  return size <= limit ? j : Vec<d>((limit / size) * j);
}

template <int d>
void applyImpulse(BodyView<d>& b, const Vec<d>& r, const Vec<d>& j) {
  if (b.inverseMass == 0) return;
  b.body->v -= j / b.body->mass;
  b.body->L -= crossArm<d>(r, j);
}

// Interpenetration resolution with particles (Sec. 4.6.1, App. B): one central object at a time,
// pushed out of every outer object intersecting it in one two-way solve (solvers/contact/push_out,
// dtau = 1 so displacements come out directly). Positions only: the velocities are untouched, so
// among dynamic bodies the mass-weighted sum of the displacements is zero (the impulses cancel).
//  * every rigid body as the central body against the free particles inside it (outer bodies
//    with q_o = 0, K_o = m_o^{-1} delta) and against the static and kinematic bodies it touches
//    (static outers, B.3: the ground does not let particles drive a box into it); a static or
//    kinematic central body decouples (B.3: each particle is moved out alone);
//  * every particle inside two or more bodies as the central body (r_o = 0: the 3x3 system of
//    eq. 4.2), its bodies the outer ones: a particle wedged between two bodies pushes both.
// Two sweeps; the rotations are linearized in the solve, so a turning body leaves second-order
// overlap for the next sweep.
constexpr int kPushOutSweeps = 2;

struct PushOutCounts {
  double deepest = 0;
  int bodySolves = 0, particleSolves = 0;
};

template <int d>
void moveBody(BodyView<d>& b, const Vec<d>& dx, const cc::AngVec<d>& theta) {
  b.body->x += dx;
  b.body->orientation = rotatedBy<d>(b.body->orientation, theta);
  b.x = b.body->x;
  b.R = b.body->rotation();
  b.inverseInertia = b.body->worldInverseInertia();
}

template <int d>
PushOutCounts pushParticlesOut(std::vector<BodyView<d>>& bodies, const std::vector<Particles<d>*>& pools,
                               double supportMargin, double tolerance) {
  PushOutCounts out;
  struct Inside {
    Particles<d>* pool;
    int i;
    double distance;
    Vec<d> n;  // out of the body
  };
  std::vector<Inside> inside;
  std::vector<std::pair<std::size_t, int>> candidates;  // (pool, particle) inside two bodies or more
  std::vector<std::size_t> hosts;
  std::vector<cc::PushOutOuter<d>> outers;
  cc::PushOutResult<d> result;
  std::vector<col::ContactPoint<d>> points;
  col::ContactQuery query;
  query.margin = supportMargin;
  auto position = [](Particles<d>* p, int i) { return Eigen::Map<Vec<d>>(&p->x[d * i]); };
  auto insideBodies = [&](std::size_t pi, int i) {
    inside.clear();
    hosts.clear();
    for (std::size_t k = 0; k < bodies.size(); ++k) {
      double distance;
      Vec<d> n;
      if (distanceTo(bodies[k], Vec<d>(position(pools[pi], i)), 0.0, distance, n) && distance < -tolerance) {
        inside.push_back({pools[pi], i, distance, n});
        hosts.push_back(k);
      }
    }
  };
  for (int sweep = 0; sweep < kPushOutSweeps; ++sweep) {
    // Particles inside two or more bodies, each the central body of its own solve, first: the
    // bodies' own solves below would push such a particle out of one body deeper into the other.
    candidates.clear();
    for (std::size_t pi = 0; pi < pools.size(); ++pi)
      for (int i = 0; i < pools[pi]->count(); ++i) {
        if (pools[pi]->fixed[i]) continue;
        int count = 0;
        for (const BodyView<d>& b : bodies) {
          double distance;
          Vec<d> n;
          if (distanceTo(b, Vec<d>(position(pools[pi], i)), 0.0, distance, n) && distance < -tolerance && ++count == 2) {
            candidates.push_back({pi, i});
            break;
          }
        }
      }
    for (const auto& [pi, i] : candidates) {
      insideBodies(pi, i);
      if (inside.size() < 2) continue;  // an earlier solve moved it
      Particles<d>* p = pools[pi];
      outers.clear();
      for (std::size_t k = 0; k < inside.size(); ++k) {
        const BodyView<d>& o = bodies[hosts[k]];
        out.deepest = std::max(out.deepest, -inside[k].distance);
        cc::PushOutOuter<d> outer;
        outer.isStatic = o.infinite;
        outer.q = Vec<d>(position(p, i)) - o.x;
        outer.mass = o.infinite ? std::numeric_limits<double>::infinity() : o.body->mass;
        outer.inertia = o.infinite ? cc::AngMat<d>::Identity() : cc::AngMat<d>(o.body->worldInertia());
        outer.displacement = -inside[k].distance * inside[k].n;  // the particle out along n
        outers.push_back(outer);
      }
      cc::PushOutCentral<d> central;
      central.mass = p->m[i];
      central.lengthScale = supportMargin;
      cc::solvePushOut<d>(central, outers, result);
      position(p, i) += result.centralDisplacement;
      for (std::size_t k = 0; k < inside.size(); ++k)
        if (!bodies[hosts[k]].infinite)
          moveBody(bodies[hosts[k]], result.outerDisplacements[k], result.outerRotations[k]);
      ++out.particleSolves;
    }
    // Every rigid body as the central body against the particles inside it.
    bool moved = false;
    for (BodyView<d>& b : bodies) {
      inside.clear();
      for (Particles<d>* p : pools)
        for (int i = 0; i < p->count(); ++i) {
          if (p->fixed[i]) continue;
          double distance;
          Vec<d> n;
          if (distanceTo(b, Vec<d>(position(p, i)), 0.0, distance, n) && distance < 0) inside.push_back({p, i, distance, n});
        }
      if (inside.empty()) continue;
      moved = true;
      for (const Inside& q : inside) out.deepest = std::max(out.deepest, -q.distance);
      if (b.infinite) {
        for (const Inside& q : inside) position(q.pool, q.i) -= q.distance * q.n;
        continue;
      }
      outers.clear();
      for (const Inside& q : inside) {
        cc::PushOutOuter<d> o;
        o.r = Vec<d>(position(q.pool, q.i)) - b.x;
        o.mass = q.pool->m[q.i];
        o.displacement = q.distance * q.n;  // d_o: from the body's surface point to the particle
        outers.push_back(o);
      }
      const std::size_t particleOuters = outers.size();
      for (const BodyView<d>& other : bodies) {
        if (!other.infinite || &other == &b) continue;
        points.clear();
        col::findContacts<d>(*other.geometry, {other.x, other.R}, *b.geometry, {b.x, b.R}, query, points);
        for (const col::ContactPoint<d>& c : points) {  // c.normal: out of b towards other
          cc::PushOutOuter<d> o;
          o.isStatic = true;
          o.r = c.point - b.x;
          o.q = c.point - other.x;
          o.mass = std::numeric_limits<double>::infinity();
          o.displacement = -std::max(c.depth, 0.0) * c.normal;
          outers.push_back(o);
        }
      }
      cc::PushOutCentral<d> central;
      central.mass = b.body->mass;
      central.inertia = b.body->worldInertia();
      central.lengthScale = b.geometry->boundingRadius();
      cc::solvePushOut<d>(central, outers, result);
      moveBody(b, result.centralDisplacement, result.centralRotation);
      for (std::size_t k = 0; k < particleOuters; ++k)
        position(inside[k].pool, inside[k].i) += result.outerDisplacements[k];
      ++out.bodySolves;
    }
    if (!moved && candidates.empty()) break;
  }
  return out;
}

}  // namespace

template <int d>
const col::PreparedGeometry<d>& PreparedShapes<d>::get(Entity e, const Shape<d>& s) {
  const std::uint64_t key = (std::uint64_t(e.index) << 32) | e.generation;
  auto it = shapes_.find(key);
  if (it == shapes_.end())
    it = shapes_.emplace(key, std::make_unique<col::PreparedGeometry<d>>(collisionGeometryOf(s))).first;
  return *it->second;
}

template <int d>
void ParticleRigidContact<d>::run(World<d>& world, StepContext& ctx) {
  // Steps II and III test the candidate positions x + dt v^{n+1/2}; Step V the split state
  // x^{n+1} + dt v^{n+1} as the rigid velocity contact does, so that a particle resting just
  // outside the contact thickness but approaching is caught before it moves in.
  const bool save = stage_ == Stage::Contact;
  const double dt = ctx.dt;
  std::vector<BodyView<d>> bodies = bodiesOf(world, shapes_, dt, true);
  if (save) {
    scratch_->savedVelocities.clear();
    world.template each<Particles<d>>([&](Entity, Particles<d>& p) { scratch_->savedVelocities.push_back(p.v); });
  }
  if (bodies.empty()) return;
  const double thickness = world.template resource<ContactSettings>().thickness;
  int impulses = 0;
  std::vector<Particles<d>*> pools;
  world.template each<Particles<d>>([&](Entity, Particles<d>& p) { pools.push_back(&p); });
  struct Touch {
    Particles<d>* pool;
    int i;
    Vec<d> r, n;
  };
  std::vector<Touch> touches;
  std::vector<cc::CentralNormalOuter<d>> outers;
  auto pointVelocity = [](const BodyView<d>& b, const Vec<d>& r) {
    return b.inverseMass == 0 && b.body->isStatic ? Vec<d>::Zero() : Vec<d>(b.body->v + angularAt<d>(b.body->omega(), r));
  };
  // Per dynamic body, its contact points with the static and kinematic bodies at this stage's
  // poses (normals out of the body), found when a particle first touches it.
  struct Support {
    const BodyView<d>* other;
    Vec<d> point, normal;
    double gap;  // separation at this stage's poses (0 if overlapping)
  };
  std::vector<std::vector<Support>> supports(bodies.size());
  std::vector<char> supportsFound(bodies.size(), 0);
  std::vector<col::ContactPoint<d>> points;
  auto supportsOf = [&](const BodyView<d>& b) -> const std::vector<Support>& {
    const std::size_t k = static_cast<std::size_t>(&b - bodies.data());
    if (supportsFound[k]) return supports[k];
    supportsFound[k] = 1;
    // Points up to 1 % of the body's size apart count, each allowed to close its gap within the
    // step (target normal velocity -gap/dt): a body floating a little above the ground is not
    // driven through it by the particles above it, nor held in the air.
    col::ContactQuery query;
    query.margin = std::max(thickness, kSupportMargin * b.geometry->minimumSize());
    for (const BodyView<d>& other : bodies) {
      if (!other.infinite) continue;
      points.clear();
      col::findContacts<d>(*b.geometry, {b.x, b.R}, *other.geometry, {other.x, other.R}, query, points);
      for (const col::ContactPoint<d>& c : points) supports[k].push_back({&other, c.pointOnA(), Vec<d>(-c.normal), std::max(0.0, -c.depth)});
    }
    return supports[k];
  };
  // One rigid body as the central body against every particle touching it (Sec. 4.7.3, eq.
  // 4.3-4.4): the normal impulses of all its contacts solved together, then Coulomb friction on
  // each contact, bounded by its normal impulse.
  auto processBody = [&](BodyView<d>& b) {
    touches.clear();
    for (Particles<d>* p : pools)
      for (int i = 0; i < p->count(); ++i) {
        if (p->fixed[i]) continue;
        const Vec<d> q = Eigen::Map<const Vec<d>>(&p->x[d * i]) + dt * Eigen::Map<const Vec<d>>(&p->v[d * i]);
        double distance;
        Vec<d> n;
        if (distanceTo(b, q, thickness, distance, n)) touches.push_back({p, i, Vec<d>(q - b.x), n});
      }
    if (touches.empty()) return;
    cc::CentralNormalBody<d> central;
    central.infinite = b.inverseMass == 0;
    if (!central.infinite) {
      central.mass = b.body->mass;
      central.inertia = b.inverseInertia.inverse();
    }
    outers.resize(touches.size());
    double particleMass = 0;
    for (std::size_t k = 0; k < touches.size(); ++k) {
      const Touch& t = touches[k];
      const Vec<d> u = Eigen::Map<const Vec<d>>(&t.pool->v[d * t.i]) - pointVelocity(b, t.r);
      outers[k] = {t.pool->m[t.i], t.r, t.n, u.dot(t.n), 0.0};
      particleMass += t.pool->m[t.i];
    }
    // The body's contacts with static and kinematic bodies join as outer bodies of (nearly)
    // infinite mass (App. B: statics as the limit of heavy bodies), so that a body squeezed
    // between particles and the ground passes their push to the ground within this one solve
    // instead of being driven into it (the rigid contact of this stage has already run).
    if (!central.infinite)
      for (const Support& s : supportsOf(b)) {
        const Vec<d> u = pointVelocity(*s.other, s.point - s.other->x) - pointVelocity(b, Vec<d>(s.point - b.x));
        outers.push_back({kSupportMassRatio * (b.body->mass + particleMass), Vec<d>(s.point - b.x), s.normal,
                          u.dot(s.normal), -s.gap / dt});
      }
    const cc::CentralNormalResult<d> normal = cc::solveCentralNormalContact<d>(central, outers);
    int pushed = 0;
    for (std::size_t k = 0; k < touches.size(); ++k)
      if (normal.lambda[k] > 0) {
        Eigen::Map<Vec<d>>(&touches[k].pool->v[d * touches[k].i]) += (normal.lambda[k] / touches[k].pool->m[touches[k].i]) * touches[k].n;
        ++pushed;
      }
    if (pushed == 0) return;
    if (!central.infinite) {
      b.body->v += normal.bodyImpulse / b.body->mass;
      b.body->L += normal.bodyAngularImpulse;
    }
    impulses += pushed;
    if (b.friction == 0) return;
    for (std::size_t k = 0; k < touches.size(); ++k) {
      if (normal.lambda[k] <= 0) continue;
      const Touch& t = touches[k];
      Eigen::Map<Vec<d>> v(&t.pool->v[d * t.i]);
      const Vec<d> j = frictionImpulse(b, t.pool->m[t.i], t.r, Vec<d>(v - pointVelocity(b, t.r)), t.n,
                                       b.friction * normal.lambda[k]);
      if (j.squaredNorm() == 0) continue;
      v += j / t.pool->m[t.i];
      applyImpulse(b, t.r, j);
    }
  };
  // Gauss-Seidel over the bodies (a particle may touch several), forward and backward in turn
  // (Sec. 4.7.3), the last sweep's direction alternating from step to step.
  for (int sweep = 0; sweep < kContactSweeps; ++sweep) {
    const bool forward = (sweep + ctx.step) % 2 == 0;
    const int nb = static_cast<int>(bodies.size());
    for (int bi = 0; bi < nb; ++bi) processBody(bodies[forward ? bi : nb - 1 - bi]);
  }
  ctx.diagnostics.set(name() + "_impulses", impulses);
}

template <int d>
void ParticlePushOut<d>::run(World<d>& world, StepContext& ctx) {
  std::vector<BodyView<d>> bodies = bodiesOf(world, shapes_, 0.0, true);
  std::vector<Particles<d>*> pools;
  world.template each<Particles<d>>([&](Entity, Particles<d>& p) { pools.push_back(&p); });
  const ContactSettings& settings = world.template resource<ContactSettings>();
  const PushOutCounts counts = pushParticlesOut<d>(bodies, pools, settings.thickness, settings.pushOutTolerance);
  ctx.diagnostics.max("particle_push_out_depth", counts.deepest);
  ctx.diagnostics.set("particle_push_out_body_solves", counts.bodySolves);
  ctx.diagnostics.set("particle_push_out_particle_solves", counts.particleSolves);
  std::size_t k = 0;
  world.template each<Particles<d>>([&](Entity, Particles<d>& p) {
    if (k < scratch_->savedVelocities.size() && scratch_->savedVelocities[k].size() == p.v.size())
      p.v = scratch_->savedVelocities[k];
    ++k;
  });
  scratch_->savedVelocities.clear();
}

template <int d>
void ParticlePenetration<d>::run(World<d>& world, StepContext& ctx) {
  const std::vector<BodyView<d>> bodies = bodiesOf(world, shapes_, 0.0, false);
  double depth = 0, ratio = 0;
  world.template each<Particles<d>>([&](Entity, Particles<d>& p) {
    // The deformable body's size: its smallest bounding-box extent (none for a single point).
    Vec<d> lo = Vec<d>::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (int i = 0; i < p.count(); ++i) {
      lo = lo.cwiseMin(Vec<d>(Eigen::Map<const Vec<d>>(&p.x[d * i])));
      hi = hi.cwiseMax(Vec<d>(Eigen::Map<const Vec<d>>(&p.x[d * i])));
    }
    const double extent = p.count() > 1 ? (hi - lo).minCoeff() : std::numeric_limits<double>::infinity();
    for (const BodyView<d>& b : bodies)
      for (int i = 0; i < p.count(); ++i) {
        if (p.fixed[i]) continue;
        double distance;
        Vec<d> n;
        if (!distanceTo(b, Vec<d>(Eigen::Map<const Vec<d>>(&p.x[d * i])), 0.0, distance, n) || distance >= 0) continue;
        depth = std::max(depth, -distance);
        const double bodySize = b.geometry->minimumSize();
        const double size = bodySize > 0 ? std::min(extent, bodySize) : extent;
        if (std::isfinite(size)) ratio = std::max(ratio, -distance / size);
      }
  });
  ctx.diagnostics.max("max_penetration", depth);
  ctx.diagnostics.max("max_penetration_ratio", ratio);
}

template <int d>
std::vector<NormalConstraint<d>> DampingSolveContacts<d>::of(World<d>& world, const Particles<d>& p, double dt,
                                                             double keep) {
  std::vector<NormalConstraint<d>> out;
  if (world.template count<Collider<d>>() == 0) return out;
  const std::vector<BodyView<d>> bodies = bodiesOf(world, shapes_, dt, false);
  const double thickness = world.template resource<ContactSettings>().thickness;
  const double tolerance = world.template resource<ContactSettings>().approachTolerance;
  std::vector<char> taken(p.count(), 0);
  for (const BodyView<d>& b : bodies)
    for (int i = 0; i < p.count(); ++i) {
      if (p.fixed[i] || taken[i]) continue;  // one contact per particle: the first body's
      const Vec<d> v = Eigen::Map<const Vec<d>>(&p.v[d * i]);
      const Vec<d> q = Eigen::Map<const Vec<d>>(&p.x[d * i]) + dt * v;
      double distance;
      Vec<d> n;
      // Resting contacts hover at about the thickness, where contact stopped them: twice it.
      if (!distanceTo(b, q, 2 * thickness, distance, n)) continue;
      const Vec<d> r = q - b.x;
      const Vec<d> bodyV = b.body->isStatic ? Vec<d>::Zero() : Vec<d>(b.body->v + angularAt<d>(b.body->omega(), r));
      const double approach = (v - bodyV).dot(n);
      if (approach > tolerance) continue;  // separating; resting contacts are held
      // A dynamic body is an unknown of the solve: the hold is on the relative normal velocity.
      // In Step V, a particle farther than the thickness from a dynamic body is not stopped by
      // the post-process this step: it is held at its own relative normal velocity, so that the
      // damping neither drives it into the body nor sees a velocity it will not have (which let
      // the damping forces do positive work on its neighbours as a body approached: row_of_balls).
      // Against static and kinematic bodies, and in Step I, every hold keeps the stage's share:
      // held at their own velocity there, the approaching particles of a stiff block landing on
      // the ground (E = 1e9) reached the contact unslowed and the energy rose 27 %.
      const bool own = !b.infinite && keep > 0 && distance >= thickness;
      const double kept = (own ? 1.0 : keep) * std::min(approach, 0.0);
      if (b.infinite) out.push_back({i, n, bodyV.dot(n) + kept, Entity{}});
      else out.push_back({i, n, kept, b.entity});
      taken[i] = 1;
    }
  return out;
}

template <int d>
std::vector<RigidConstraintRow<d>> DampingSolveContacts<d>::rigidRows(World<d>& world, std::vector<Entity>& unknowns,
                                                                     double dt, double keep) {
  using Twist = solvers::deformable::DampingTwist<d>;
  std::vector<RigidConstraintRow<d>> out;
  if (unknowns.empty()) return out;
  auto dynamic = [&](Entity e) {
    const RigidBody<d>* b = world.template get<RigidBody<d>>(e);
    return b && !b->isStatic && !world.template has<KinematicMotion<d>>(e);
  };
  auto known = [&](Entity e) { return std::find(unknowns.begin(), unknowns.end(), e) != unknowns.end(); };
  auto row = [](const Vec<d>& n, const Vec<d>& r) {
    Twist g;
    g.template head<d>() = n;
    g.template tail<cc::kAngularDim<d>>() = crossArm<d>(r, n);
    return g;
  };
  // Contacts: every unknown against every body with a collider, at the candidate poses.
  std::vector<BodyView<d>> bodies;
  if (world.template count<Collider<d>>() > 0) bodies = bodiesOf(world, shapes_, dt, false);
  auto viewOf = [&](Entity e) -> const BodyView<d>* {
    for (const BodyView<d>& b : bodies)
      if (b.entity == e) return &b;
    return nullptr;
  };
  const double thickness = world.template resource<ContactSettings>().thickness;
  const double tolerance = world.template resource<ContactSettings>().approachTolerance;
  std::vector<col::ContactPoint<d>> points;
  // Joints: the assembly's rows (3-D solver; a 2-D world's joints are planar: linear rows in the
  // plane, angular rows about z).
  std::unique_ptr<JointAssembly<d>> joints;
  std::vector<solvers::JointRows> jointRows;
  std::vector<char> jointDone;
  if (world.template count<ArticulationJoint<d>>() > 0) {
    joints = std::make_unique<JointAssembly<d>>(world);
    jointRows = joints->rows();
    jointDone.assign(jointRows.size(), 0);
  }
  auto lower = [](const Eigen::Vector3d& v) -> Vec<d> { return v.template head<d>(); };
  auto angular = [](const Eigen::Vector3d& w) -> AngularVec<d> {
    if constexpr (d == 3) return w;
    else return AngularVec<2>(w.z());
  };
  for (std::size_t k = 0; k < unknowns.size(); ++k) {  // grows as bodies are found
    const Entity a = unknowns[k];
    if (const BodyView<d>* va = viewOf(a)) {
      col::ContactQuery query;
      query.margin = std::max(2 * thickness, kSupportMargin * va->geometry->minimumSize());
      const Vec<d> vA = va->body->v;
      const AngularVec<d> wA = va->body->omega();
      for (const BodyView<d>& vb : bodies) {
        if (vb.entity == a) continue;
        const bool other = dynamic(vb.entity);
        // A pair of unknowns once: from the one found first.
        if (other && known(vb.entity) &&
            std::find(unknowns.begin(), unknowns.end(), vb.entity) - unknowns.begin() < static_cast<std::ptrdiff_t>(k))
          continue;
        if (!va->geometry->unbounded() && !vb.geometry->unbounded() &&
            (va->x - vb.x).norm() > va->geometry->boundingRadius() + vb.geometry->boundingRadius() + query.margin)
          continue;
        points.clear();
        col::findContacts<d>(*va->geometry, {va->x, va->R}, *vb.geometry, {vb.x, vb.R}, query, points);
        bool touching = false;
        for (const col::ContactPoint<d>& c : points) {
          const Vec<d> n = c.normal;  // out of b towards a
          const Vec<d> ra = c.point - va->x, rb = c.point - vb.x;
          const Vec<d> pointA = vA + angularAt<d>(wA, ra);
          const Vec<d> pointB = vb.body->isStatic ? Vec<d>::Zero() : Vec<d>(vb.body->v + angularAt<d>(vb.body->omega(), rb));
          const double approach = (pointA - pointB).dot(n);
          // A separating point is held at its own relative normal velocity: left out, an equality
          // on the other points of a manifold would let the body turn into the support about them
          // inside the solve (a light box under a block, held at one or two of its four corners,
          // tipped into the ground in the solve and the block's damping saw that motion).
          const double gap = std::max(0.0, -c.depth);
          const bool own = approach > tolerance || (other && keep > 0 && gap >= thickness);
          const double kept = own ? approach : keep * std::min(approach, 0.0);
          RigidConstraintRow<d> r;
          r.a = a;
          r.ga = row(n, ra);
          if (other) {
            r.b = vb.entity;
            r.gb = -row(n, rb);
            r.target = kept;
          } else {
            r.gb = Twist::Zero();
            r.target = kept + pointB.dot(n);
          }
          out.push_back(r);
          touching = true;
        }
        if (touching && other && !known(vb.entity)) unknowns.push_back(vb.entity);
      }
    }
    if (!joints) continue;
    for (std::size_t j = 0; j < jointRows.size(); ++j) {
      if (jointDone[j]) continue;
      const solvers::JointRows& jr = jointRows[j];
      const Entity parent = joints->entity[jr.parent], child = joints->entity[jr.child];
      if (parent != a && child != a) continue;
      jointDone[j] = 1;
      const bool parentFree = jr.parent != 0 && dynamic(parent), childFree = jr.child != 0 && dynamic(child);
      const solvers::ConstraintBody& bp = joints->bodies[jr.parent];
      const solvers::ConstraintBody& bc = joints->bodies[jr.child];
      for (int i = 0; i < jr.rows(); ++i) {
        // Row velocity: n . (v_c + w_c x r_c - v_p - w_p x r_p) or e . (w_c - w_p).
        Twist gp = Twist::Zero(), gc = Twist::Zero();
        if (i < jr.linear) {
          const Vec<d> n = lower(jr.linearDirs.col(i));
          gc = row(n, lower(jr.armChild));
          gp = -row(n, lower(jr.armParent));
        } else {
          const AngularVec<d> e = angular(jr.angularDirs.col(i - jr.linear));
          gc.template tail<cc::kAngularDim<d>>() = e;
          gp.template tail<cc::kAngularDim<d>>() = -e;
        }
        auto twistOf = [&](const solvers::ConstraintBody& b) {
          Twist t;
          t.template head<d>() = lower(b.v);
          t.template tail<cc::kAngularDim<d>>() = angular(b.w);
          return t;
        };
        RigidConstraintRow<d> r;
        if (childFree) {
          r.a = child;
          r.ga = gc;
          if (parentFree) {
            r.b = parent;
            r.gb = gp;
          } else {
            r.target = -gp.dot(twistOf(bp));
          }
        } else {
          r.a = parent;
          r.ga = gp;
          r.target = -gc.dot(twistOf(bc));
        }
        out.push_back(r);
      }
      const Entity otherEnd = parent == a ? child : parent;
      if ((parent == a ? childFree : parentFree) && !known(otherEnd)) unknowns.push_back(otherEnd);
    }
  }
  return out;
}

template <int d>
std::vector<std::unique_ptr<System<d>>> makeParticleContactSystems() {
  auto scratch = std::make_shared<ParticleContactScratch>();
  std::vector<std::unique_ptr<System<d>>> out;
  out.push_back(std::make_unique<ParticleRigidContact<d>>(Stage::Contact, scratch));
  out.push_back(std::make_unique<ParticlePushOut<d>>(scratch));
  out.push_back(std::make_unique<ParticleRigidContact<d>>(Stage::AdvanceVelocity, scratch));
  out.push_back(std::make_unique<ParticlePenetration<d>>());
  return out;
}

template <int d>
std::vector<std::unique_ptr<System<d>>> makeParticleCollisionSystems() {
  std::vector<std::unique_ptr<System<d>>> out;
  out.push_back(std::make_unique<ParticleRigidContact<d>>(Stage::Collisions, std::make_shared<ParticleContactScratch>()));
  return out;
}

template class DampingSolveContacts<2>;
template class DampingSolveContacts<3>;
template class PreparedShapes<2>;
template class PreparedShapes<3>;
template class ParticleRigidContact<2>;
template class ParticleRigidContact<3>;
template class ParticlePushOut<2>;
template class ParticlePushOut<3>;
template class ParticlePenetration<2>;
template class ParticlePenetration<3>;
template std::vector<std::unique_ptr<System<2>>> makeParticleContactSystems<2>();
template std::vector<std::unique_ptr<System<3>>> makeParticleContactSystems<3>();
template std::vector<std::unique_ptr<System<2>>> makeParticleCollisionSystems<2>();
template std::vector<std::unique_ptr<System<3>>> makeParticleCollisionSystems<3>();

}  // namespace monolith

#include "systems/particle_contact.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <limits>

#include "solvers/collision/collision_impl.h"
#include "systems/contact_workspace.h"

namespace monolith {

namespace col = solvers::collision;

namespace {

constexpr int kContactSweeps = 4;

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
  const col::PreparedGeometry<d>* geometry = nullptr;
  Vec<d> x;
  MatD<d> R;
  double inverseMass = 0;
  InertiaMat<d> inverseInertia = InertiaMat<d>::Zero();
  double friction = 0;
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
    v.geometry = &shapes.get(e, s);
    const bool infinite = b.isStatic || world.template has<KinematicMotion<d>>(e);
    v.x = b.x + candidateDt * (b.isStatic ? Vec<d>::Zero() : b.v);
    v.R = b.isStatic || candidateDt == 0 ? b.rotation() : candidateRotation(b, candidateDt);
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

// The impulse on the particle (minus on the body) that stops an approach along n, with
// Coulomb friction of coefficient mu; zero when not approaching.
template <int d>
Vec<d> contactImpulse(const BodyView<d>& b, double particleMass, const Vec<d>& r, const Vec<d>& u, const Vec<d>& n) {
  const double vn = u.dot(n);
  if (vn >= 0) return Vec<d>::Zero();
  MatD<d> K;  // relative velocity change per unit impulse on the particle
  for (int k = 0; k < d; ++k) {
    const Vec<d> e = Vec<d>::Unit(k);
    K.col(k) = e / particleMass + bodyResponse(b, r, e);
  }
  const Vec<d> stick = K.lu().solve(-u);
  const double jn = stick.dot(n);
  if ((stick - jn * n).norm() <= b.friction * jn) return stick;
  const Vec<d> ut = u - vn * n;
  const Vec<d> t = ut.norm() > 0 ? Vec<d>(ut.normalized()) : Vec<d>::Zero();
  const Vec<d> dir = n - b.friction * t;
  double denom = n.dot(K * dir);
  if (denom > 0) return (-vn / denom) * dir;
  denom = n.dot(K * n);
  return (-vn / denom) * n;
}

template <int d>
void applyImpulse(BodyView<d>& b, const Vec<d>& r, const Vec<d>& j) {
  if (b.inverseMass == 0) return;
  b.body->v -= j / b.body->mass;
  b.body->L -= crossArm<d>(r, j);
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
  const bool candidate = stage_ != Stage::AdvanceVelocity;
  const bool save = stage_ == Stage::Contact;
  const double dt = ctx.dt;
  std::vector<BodyView<d>> bodies = bodiesOf(world, shapes_, candidate ? dt : 0.0, !save);
  if (save) {
    scratch_->savedVelocities.clear();
    world.template each<Particles<d>>([&](Entity, Particles<d>& p) { scratch_->savedVelocities.push_back(p.v); });
  }
  if (bodies.empty()) return;
  const double thickness = world.settings().contact.thickness;
  int impulses = 0;
  std::vector<Particles<d>*> pools;
  world.template each<Particles<d>>([&](Entity, Particles<d>& p) { pools.push_back(&p); });
  auto visit = [&](BodyView<d>& b, Particles<d>& p, int i) {
    if (p.fixed[i]) return;
    Eigen::Map<Vec<d>> v(&p.v[d * i]);
    const Vec<d> x = Eigen::Map<const Vec<d>>(&p.x[d * i]);
    const Vec<d> q = candidate ? Vec<d>(x + dt * v) : x;
    double distance;
    Vec<d> n;
    if (!distanceTo(b, q, thickness, distance, n)) return;
    const Vec<d> r = q - b.x;
    const Vec<d> bodyV = b.inverseMass == 0 && b.body->isStatic ? Vec<d>::Zero()
                                                                : Vec<d>(b.body->v + angularAt<d>(b.body->omega(), r));
    const Vec<d> j = contactImpulse(b, p.m[i], r, Vec<d>(v - bodyV), n);
    if (j.squaredNorm() == 0) return;
    v += j / p.m[i];
    applyImpulse(b, r, j);
    ++impulses;
  };
  // Forward and backward sweeps in turn (Sec. 4.7.3), the last sweep's direction alternating from
  // step to step: sweeping one way lets the first particles' friction impulses turn the body
  // before the later ones are visited, a bias that walked a stack of boxes sideways along the
  // particle numbering (more sweeps in a fixed order did not remove it: measured with 12).
  for (int sweep = 0; sweep < kContactSweeps; ++sweep) {
    const bool forward = (sweep + ctx.step) % 2 == 0;
    const int nb = static_cast<int>(bodies.size()), np = static_cast<int>(pools.size());
    for (int bi = 0; bi < nb; ++bi) {
      BodyView<d>& b = bodies[forward ? bi : nb - 1 - bi];
      for (int pi = 0; pi < np; ++pi) {
        Particles<d>& p = *pools[forward ? pi : np - 1 - pi];
        const int n = p.count();
        for (int i = 0; i < n; ++i) visit(b, p, forward ? i : n - 1 - i);
      }
    }
  }
  ctx.diagnostics.set(name() + "_impulses", impulses);
}

template <int d>
void ParticlePushOut<d>::run(World<d>& world, StepContext& ctx) {
  std::vector<BodyView<d>> bodies = bodiesOf(world, shapes_, 0.0, false);
  double deepest = 0;
  for (const BodyView<d>& b : bodies) {
    world.template each<Particles<d>>([&](Entity, Particles<d>& p) {
      for (int i = 0; i < p.count(); ++i) {
        if (p.fixed[i]) continue;
        Eigen::Map<Vec<d>> x(&p.x[d * i]);
        double distance;
        Vec<d> n;
        if (!distanceTo(b, Vec<d>(x), 0.0, distance, n) || distance >= 0) continue;
        deepest = std::max(deepest, -distance);
        x -= distance * n;
      }
    });
  }
  ctx.diagnostics.max("particle_push_out_depth", deepest);
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

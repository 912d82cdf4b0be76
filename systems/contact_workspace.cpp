#include "systems/contact_workspace.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "solvers/contact/energy_clamp.h"
#include "solvers/contact/impulse.h"

namespace monolith {

namespace col = solvers::collision;
namespace con = solvers::contact;

template <int d>
col::Geometry<d> collisionGeometryOf(const Shape<d>& shape) {
  col::Geometry<d> g;
  g.halfExtents = shape.halfExtents;
  g.radius = shape.radius;
  g.halfHeight = shape.halfHeight;
  switch (shape.type) {
    case ShapeType::Box: g.type = col::GeometryType::Box; break;
    case ShapeType::Sphere: g.type = col::GeometryType::Sphere; break;
    case ShapeType::Capsule: g.type = col::GeometryType::Capsule; break;
    case ShapeType::Cylinder: g.type = col::GeometryType::Cylinder; break;
    case ShapeType::Plane:
      g.type = col::GeometryType::HalfSpace;
      g.normal = shape.normal;
      g.offset = 0;
      break;
    case ShapeType::Convex: g.type = col::GeometryType::Convex; break;
    case ShapeType::Mesh: g.type = col::GeometryType::Mesh; break;
  }
  for (int i = 0; i < shape.vertexCount(); ++i) g.vertices.push_back(shape.vertex(i));
  for (std::size_t i = 0; i + 2 < shape.triangles.size(); i += 3)
    g.triangles.push_back({shape.triangles[i], shape.triangles[i + 1], shape.triangles[i + 2]});
  return g;
}

namespace {

// exp(theta*) q: rotation by the rotation vector theta applied in the world frame.
template <int d>
Orientation<d> rotated(const Orientation<d>& q, const con::AngVec<d>& theta) {
  if constexpr (d == 3) {
    const double angle = theta.norm();
    if (angle == 0) return q;
    return (Eigen::Quaterniond(Eigen::AngleAxisd(angle, theta / angle)) * q).normalized();
  } else {
    return q + theta(0);
  }
}

template <int d>
Eigen::Matrix<double, d, d> rotationOf(const Orientation<d>& q) {
  if constexpr (d == 3) return q.toRotationMatrix();
  else return Eigen::Rotation2Dd(q).toRotationMatrix();
}

}  // namespace

template <int d>
void ContactWorkspace<d>::ensureGeometry(World<d>& world) {
  std::vector<Entity> current;
  world.template each<Collider<d>, RigidBody<d>, Shape<d>>(
      [&](Entity e, Collider<d>&, RigidBody<d>&, Shape<d>&) { current.push_back(e); });
  if (current == entities_ && !geometries_.empty()) return;
  entities_ = current;
  geometries_.clear();
  for (Entity e : entities_)
    geometries_.push_back(std::make_unique<col::PreparedGeometry<d>>(collisionGeometryOf(*world.template get<Shape<d>>(e))));
}

template <int d>
bool ContactWorkspace<d>::pack(World<d>& world, double stepDt, bool subtractKick) {
  ensureGeometry(world);
  dt = stepDt;
  kick = subtractKick;
  settings = world.settings().contact;
  gravity = world.settings().gravity;
  bodies.resize(entities_.size());
  for (std::size_t i = 0; i < entities_.size(); ++i) {
    const Entity e = entities_[i];
    RigidBody<d>* rb = world.template get<RigidBody<d>>(e);
    const Collider<d>* c = world.template get<Collider<d>>(e);
    ContactBody<d>& b = bodies[i];
    b.body = rb;
    b.geometry = geometries_[i].get();
    b.isStatic = rb->isStatic;
    b.kinematic = world.template has<KinematicMotion<d>>(e);
    b.frozen = false;
    b.mass = rb->mass;
    b.restitution = c->restitution;
    b.friction = c->friction;
    b.x0 = rb->x;
    b.q0 = rb->orientation;
    b.R0 = rotationOf<d>(rb->orientation);
    b.inverseInertia0 = rb->worldInverseInertia();
    b.inertia0 = rb->worldInertia();
    b.v = rb->v;
    b.L = rb->L;
    b.dv.setZero();
    b.dL.setZero();
    if (subtractKick && !b.infinite()) {
      if (const RigidForces<d>* f = world.template get<RigidForces<d>>(e)) {
        b.dv = (0.5 * dt / b.mass) * f->force;
        b.dL = 0.5 * dt * f->torque;
      }
      b.v -= b.dv;
      b.L -= b.dL;
    }
    b.movedStamp = 0;
  }
  updateAllCandidates();
  return !bodies.empty();
}

template <int d>
void ContactWorkspace<d>::unpack(bool positions) {
  for (ContactBody<d>& b : bodies) {
    if (b.isStatic || b.kinematic) continue;
    b.body->v = b.v;
    b.body->L = b.L;
    if (positions) {
      b.body->x = b.x0;
      b.body->orientation = b.q0;
    }
  }
}

template <int d>
void ContactWorkspace<d>::updateCandidate(ContactBody<d>& b) const {
  if (b.isStatic) {
    b.candidate.x = b.x0;
    b.candidate.R = b.R0;
    return;
  }
  const double k = kick ? 1.0 : 0.0;
  b.candidate.x = b.x0 + dt * (b.v + k * b.dv);
  const con::AngVec<d> w = b.inverseInertia0 * (b.L + k * b.dL);
  b.candidate.R = rotationOf<d>(rotated<d>(b.q0, dt * w));
}

template <int d>
void ContactWorkspace<d>::updateAllCandidates() {
  for (auto& b : bodies) updateCandidate(b);
}

template <int d>
void ContactWorkspace<d>::setCandidateToBase(ContactBody<d>& b) const {
  b.candidate.x = b.x0;
  b.candidate.R = b.R0;
}

template <int d>
void ContactWorkspace<d>::findPairs() {
  const int n = static_cast<int>(bodies.size());
  boxes_.resize(n);
  infinite_.resize(n);
  for (int i = 0; i < n; ++i) {
    ContactBody<d>& b = bodies[i];
    // The box covers both the base and the candidate pose (the swept region of the step), so
    // pairs that only touch at one end are not missed.
    Eigen::AlignedBox<double, d> box = col::worldBounds(*b.geometry, b.candidate);
    col::Pose<d> base;
    base.x = b.x0;
    base.R = b.R0;
    box.extend(col::worldBounds(*b.geometry, base));
    const VecD pad = VecD::Constant(settings.thickness);
    box.min() -= pad;
    box.max() += pad;
    boxes_[i] = box;
    infinite_[i] = (b.isStatic || b.kinematic) ? 1 : 0;
  }
  if (!broadPhase_) broadPhase_ = std::make_unique<col::BroadPhase<d>>();
  const auto& found = broadPhase_->findPairs(boxes_, infinite_);
  pairs.assign(found.size(), ContactPairState{});
  for (std::size_t k = 0; k < found.size(); ++k) {
    pairs[k].a = found[k].first;
    pairs[k].b = found[k].second;
  }
  islands = con::computeIslands(n, found, infinite_);
  islandPairsByLevel = islands.pairs;
}

template <int d>
void ContactWorkspace<d>::computeLevels() {
  // "a below b" when b, re-advanced with its new velocity (with the Step I kick), overlaps a
  // advanced with its old one (notes 1.6). Bodies of infinite mass are never re-advanced, so
  // they end up at the bottom.
  std::vector<std::pair<int, int>> edges;
  col::Pose<d> oldA, oldB, newA, newB;
  auto poseWith = [&](const ContactBody<d>& b, double k) {
    col::Pose<d> p;
    if (b.isStatic) {
      p.x = b.x0;
      p.R = b.R0;
      return p;
    }
    p.x = b.x0 + dt * (b.v + k * b.dv);
    p.R = rotationOf<d>(rotated<d>(b.q0, dt * (b.inverseInertia0 * (b.L + k * b.dL))));
    return p;
  };
  for (const ContactPairState& pair : pairs) {
    if (!pair.processed) continue;
    const ContactBody<d>& A = bodies[pair.a];
    const ContactBody<d>& B = bodies[pair.b];
    if (!(A.isStatic || A.kinematic) &&
        col::overlaps(*A.geometry, poseWith(A, 1.0), *B.geometry, poseWith(B, 0.0)))
      edges.emplace_back(pair.b, pair.a);
    if (!(B.isStatic || B.kinematic) &&
        col::overlaps(*B.geometry, poseWith(B, 1.0), *A.geometry, poseWith(A, 0.0)))
      edges.emplace_back(pair.a, pair.b);
  }
  levels = con::computeLevels(static_cast<int>(bodies.size()), edges);
  for (ContactPairState& pair : pairs) pair.level = std::max(levels.levelOf[pair.a], levels.levelOf[pair.b]);
  islandPairsByLevel.resize(islands.pairs.size());
  for (std::size_t i = 0; i < islands.pairs.size(); ++i) {
    auto& list = islandPairsByLevel[i];
    list.clear();
    for (int p : islands.pairs[i])
      if (pairs[p].processed) list.push_back(p);
    std::stable_sort(list.begin(), list.end(), [&](int x, int y) { return pairs[x].level < pairs[y].level; });
  }
}

template <int d>
int ContactWorkspace<d>::updatePair(ContactPairState& pair, ImpulseMode mode, double epsilon, int iterations,
                                   double margin, std::vector<col::ContactPoint<d>>& scratch,
                                   double* clampEnergyChange, int* clampsApplied) {
  ContactBody<d>& A = bodies[pair.a];
  ContactBody<d>& B = bodies[pair.b];
  if (A.infinite() && B.infinite()) return 0;
  const bool collision = mode == ImpulseMode::Collision;
  con::ImpulseSettings impulse;
  impulse.friction = std::min(A.friction, B.friction);
  if (collision) {
    impulse.restitution = std::min(A.restitution, B.restitution);
    impulse.clampFrictionMagnitude = impulse.restitution != 0;
  } else {
    impulse.restitution = -1.0 + epsilon;
  }
  const bool clamp = settings.energyClamp && mode != ImpulseMode::Contact;
  col::ContactQuery query;
  query.margin = margin;
  int applied = 0;
  for (int it = 0; it < iterations; ++it) {
    scratch.clear();
    if (col::findContacts(*A.geometry, A.candidate, *B.geometry, B.candidate, query, scratch) == 0) break;
    if (collision) pair.processed = true;
    // Lever arms and normals are those of the split state (candidate positions), as GBF 2003
    // and Sec. 2.3.2 compute them: the contact point relative to each candidate centre of mass.
    // (Mapping the point back through the body's rotation to time n, as the level-set code
    // does for surface vertices, is wrong for round shapes: a rolling disk's deepest point is
    // not a material point, and the mapped lever arm would lag by the step's rotation.)
    int best = -1;
    double bestDepth = -margin;
    VecD bestRa, bestRb, bestN, bestVrel;
    for (int k = 0; k < static_cast<int>(scratch.size()); ++k) {
      const auto& c = scratch[k];
      if (c.depth < bestDepth || (best >= 0 && c.depth == bestDepth)) continue;
      const VecD ra = c.point - A.candidate.x, rb = c.point - B.candidate.x, n = c.normal;
      const VecD vrel = A.pointVelocity(ra) - B.pointVelocity(rb);
      if (vrel.dot(n) >= -settings.approachTolerance) continue;
      best = k;
      bestDepth = c.depth;
      bestRa = ra;
      bestRb = rb;
      bestN = n;
      bestVrel = vrel;
    }
    if (best < 0) break;
    con::ImpulseBody<d> ia{A.inverseMass(), A.inverseInertia(), bestRa};
    con::ImpulseBody<d> ib{B.inverseMass(), B.inverseInertia(), bestRb};
    const Eigen::Matrix<double, d, d> K = con::impulseFactor(ia) + con::impulseFactor(ib);
    VecD j = con::pointImpulse<d>(K, bestVrel, bestN, impulse);
    if (clamp) {
      // Energy of the non-split base state; a partner of infinite mass that moves (kinematic)
      // is handled in its frame: the dynamic body's velocity relative to its point velocity.
      con::ClampBody<d> ca{A.inverseMass(), A.inverseInertia(), A.v, A.L, bestRa};
      con::ClampBody<d> cb{B.inverseMass(), B.inverseInertia(), B.v, B.L, bestRb};
      if (B.infinite()) ca.velocity = A.v - B.pointVelocity(bestRb), cb.velocity.setZero(), cb.angularMomentum.setZero();
      if (A.infinite()) cb.velocity = B.v - A.pointVelocity(bestRa), ca.velocity.setZero(), ca.angularMomentum.setZero();
      const con::ClampResult r = con::clampImpulseEnergy<d>(ca, cb, j);
      if (r.kind != con::ClampResult::Case::NoGain && clampsApplied) ++*clampsApplied;
      if (clampEnergyChange) *clampEnergyChange += r.energyChange;
      j *= r.scale;
    }
    if (j.squaredNorm() == 0) break;
    if (!A.infinite()) {
      A.v += A.inverseMass() * j;
      A.L += con::cross<d>(bestRa, j);
      updateCandidate(A);
    }
    if (!B.infinite()) {
      B.v -= B.inverseMass() * j;
      B.L -= con::cross<d>(bestRb, j);
      updateCandidate(B);
    }
    if (mode != ImpulseMode::Collision) pair.contacted = true;
    ++applied;
  }
  return applied;
}

template col::Geometry<2> collisionGeometryOf<2>(const Shape<2>&);
template col::Geometry<3> collisionGeometryOf<3>(const Shape<3>&);
template class ContactWorkspace<2>;
template class ContactWorkspace<3>;

}  // namespace monolith

#include "systems/contact_workspace.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "components/joint.h"
#include "solvers/collision/grounded_box.h"
#include "solvers/contact/energy_clamp.h"
#include "solvers/contact/impulse.h"
#include "solvers/contact/manifold_problem.h"
#include "solvers/contact/stable_key_sort.h"

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

template <int d>
Eigen::Matrix<double, d, d> rotationOf(const Orientation<d>& q) {
  if constexpr (d == 3) return q.toRotationMatrix();
  else return Eigen::Rotation2Dd(q).toRotationMatrix();
}

// False when the bodies' bounding balls (about their centres of mass, at the candidate poses)
// are farther apart than the margin: no contact is possible, the narrow phase can be skipped.
template <int d>
bool mayTouch(const ContactBody<d>& a, const ContactBody<d>& b, double margin) {
  const double reach = a.geometry->boundingRadius() + b.geometry->boundingRadius() + margin;
  return !std::isfinite(reach) || (a.candidate.x - b.candidate.x).squaredNorm() <= reach * reach;
}

// False when no contact point of the pair can approach faster than `tolerance` (a collision
// update would then apply nothing): |v_n| <= |v_a - v_b| + |w_a| l_a + |w_b| l_b, with l the
// lever arm's bound. A reported point lies half its depth off a body's surface and the depth is
// at most the smaller body's width, so l_a <= r_a + min(r_a, r_b) + margin. A settled pile's
// time-n velocities are ~1e-13 m/s: its collision sweep then needs no manifolds.
template <int d>
bool mayApproach(const ContactBody<d>& a, const ContactBody<d>& b, const con::AngMat<d>& splitA,
                 const con::AngMat<d>& splitB, double margin, double tolerance) {
  const double ra = a.geometry->boundingRadius(), rb = b.geometry->boundingRadius();
  const double shorter = std::min(ra, rb);
  auto spin = [&](const con::AngMat<d>& split, const con::AngVec<d>& L, double r) {
    const double w = (split * L).norm();
    return w == 0 ? 0.0 : w * (r + shorter + margin);  // an unturning plane adds nothing (0 * inf)
  };
  const double bound = (a.v - b.v).norm() + spin(splitA, a.L, ra) + spin(splitB, b.L, rb);
  // Half the tolerance: the bound and the points' v_n round differently.
  return !(bound <= 0.5 * tolerance);
}

// The world inverse inertia of a body turned to `pose` (what updateCandidate sets for the
// candidate pose; a static body keeps its base one).
template <int d>
con::AngMat<d> splitInverseInertiaAt(const ContactBody<d>& b, const col::Pose<d>& pose) {
  if constexpr (d == 3) {
    if (!b.still()) return pose.R * b.body->inertiaBodyInverse * pose.R.transpose();
  }
  return b.inverseInertia0;
}

// The manifold problem of the thread's contact updates (ContactWorkspace::findPairImpulse and
// updateBodyAgainstFrozen): its storage is kept from update to update.
template <int d>
con::ManifoldProblem<d>& threadProblem() {
  thread_local con::ManifoldProblem<d> problem;
  return problem;
}

// The targets of a contact update's points (ManifoldProblem::add).
inline con::ManifoldTargets targetsOf(const ContactSettings& settings, double dt, double restitution, bool closeGaps) {
  con::ManifoldTargets t;
  t.restitution = restitution;
  t.closeGaps = closeGaps;
  t.dt = dt;
  t.gapTolerance = settings.pushOutTolerance;
  t.approachTolerance = settings.approachTolerance;
  return t;
}

// The normal impulse a pair's friction may still lean on in this stage (shock propagation):
// Coulomb's law over the stage's impulses, |F| <= mu N, less what its friction has used.
double stageAllowance(const ContactPairState& pair, double mu) {
  if (!(mu > 0)) return 0;
  const auto& f = pair.stageFriction;
  return std::max(0.0, pair.stageNormal - std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]) / mu);
}

// Adds a solved update's impulses (on body `a` of the pair when sign = 1, on `b` when -1; the
// clamp's scale applied) to the pair's stage sums.
template <int d>
void addToStage(ContactPairState& pair, const con::PgsPoint<d>* begin, const con::PgsPoint<d>* end, double scale,
                double sign) {
  for (const con::PgsPoint<d>* p = begin; p != end; ++p) {
    pair.stageNormal += scale * p->normalImpulse;
    const Eigen::Matrix<double, d, 1> f = p->T * p->tangentImpulse;
    for (int k = 0; k < d; ++k) pair.stageFriction[k] += sign * scale * f[k];
  }
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
  centreShift_.assign(entities_.size(), VecD::Zero());
  // Static boxes standing on a static half-space reach down through it, and those standing on
  // another static box reach into it (grounded_box.h): the bodies' poses are those of the scene,
  // as statics never move, and the supports are the boxes as the scene gives them.
  std::vector<col::HalfSpaceInWorld<d>> grounds;
  std::vector<col::BoxInWorld<d>> supports;
  for (Entity e : entities_) {
    const RigidBody<d>& rb = *world.template get<RigidBody<d>>(e);
    const Shape<d>& shape = *world.template get<Shape<d>>(e);
    if (!rb.isStatic) continue;
    if (shape.type == ShapeType::Plane) grounds.push_back({rotationOf<d>(rb.orientation) * shape.normal, rb.x});
    const col::Geometry<d> g = collisionGeometryOf(shape);
    if (g.type == col::GeometryType::Box) supports.push_back({{rb.x, rotationOf<d>(rb.orientation)}, g.halfExtents});
  }
  for (std::size_t i = 0; i < entities_.size(); ++i) {
    const RigidBody<d>& rb = *world.template get<RigidBody<d>>(entities_[i]);
    col::Geometry<d> g = collisionGeometryOf(*world.template get<Shape<d>>(entities_[i]));
    if (rb.isStatic && g.type == col::GeometryType::Box && (!grounds.empty() || supports.size() > 1)) {
      col::Pose<d> pose;
      pose.x = rb.x;
      pose.R = rotationOf<d>(rb.orientation);
      // A face within the push-out tolerance of the plane or the support stands on it.
      centreShift_[i] =
          col::extendBoxThroughGround<d>(g, pose, grounds, world.template resource<ContactSettings>().pushOutTolerance, supports);
    }
    geometries_.push_back(std::make_unique<col::PreparedGeometry<d>>(g));
  }
  jointedPairs_.clear();
  if (const auto* joints = world.template findPool<ArticulationJoint<d>>()) {
    std::map<std::uint32_t, int> index;
    for (std::size_t i = 0; i < entities_.size(); ++i) index[entities_[i].index] = static_cast<int>(i);
    auto bodyOf = [&](const std::string& name) {
      const auto e = world.find(name);
      const auto it = e ? index.find(e->index) : index.end();
      return it == index.end() ? -1 : it->second;
    };
    for (const ArticulationJoint<d>& j : joints->components()) {
      const int a = bodyOf(j.parent), b = bodyOf(j.child);
      if (a >= 0 && b >= 0) jointedPairs_.emplace_back(std::min(a, b), std::max(a, b));
    }
    std::sort(jointedPairs_.begin(), jointedPairs_.end());
    jointedPairs_.erase(std::unique(jointedPairs_.begin(), jointedPairs_.end()), jointedPairs_.end());
  }
}

template <int d>
bool ContactWorkspace<d>::pack(World<d>& world, double dt, bool subtractKick) {
  ensureGeometry(world);
  const CandidateStep step{dt, subtractKick};  // the candidates of the stage that packs
  settings = world.template resource<ContactSettings>();
  gravity = world.settings().gravity;
  bodies.resize(entities_.size());
  // The pools once (World::get looks each up by name), then the bodies in parallel: each writes
  // only its own slot, so the result does not depend on the thread count.
  auto& rigidBodies = world.template pool<RigidBody<d>>();
  const auto& colliders = world.template pool<Collider<d>>();
  const auto* kinematics = world.template findPool<KinematicMotion<d>>();
  const auto* forces = world.template findPool<RigidForces<d>>();
  const auto* sleeps = world.template findPool<Sleep<d>>();
  auto packRange = [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const Entity e = entities_[i];
      RigidBody<d>* rb = rigidBodies.get(e);
      const Collider<d>* c = colliders.get(e);
      ContactBody<d>& b = bodies[i];
      b.body = rb;
      b.geometry = geometries_[i].get();
      b.isStatic = rb->isStatic;
      b.kinematic = kinematics && kinematics->get(e);
      b.asleep = isAsleep<d>(sleeps, e);
      b.frozen = false;
      b.mass = rb->mass;
      b.restitution = c->restitution;
      b.friction = c->friction;
      b.x0 = rb->x;
      b.q0 = rb->orientation;
      b.R0 = rotationOf<d>(rb->orientation);
      if (b.isStatic) b.x0 += b.R0 * centreShift_[i];  // the centre of its collision box
      b.inverseInertia0 = rb->worldInverseInertia();
      b.inertia0 = rb->worldInertia();
      b.v = rb->v;
      b.L = rb->L;
      b.dv.setZero();
      b.dL.setZero();
      if (subtractKick && !b.infinite()) {
        if (const RigidForces<d>* f = forces ? forces->get(e) : nullptr) {
          b.dv = (0.5 * dt / b.mass) * f->force;
          b.dL = 0.5 * dt * f->torque;
        }
        b.v -= b.dv;
        b.L -= b.dL;
      }
      b.movedStamp = 0;
      b.turnFree = false;
      if constexpr (d == 3) {
        const auto& I = rb->inertiaBodyInverse;
        b.turnFree = b.geometry->geometry().type == col::GeometryType::Sphere && I.isDiagonal(0) &&
                     I(0, 0) == I(1, 1) && I(1, 1) == I(2, 2);
      }
      updateCandidate(b, step);
    }
  };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, entities_.size(), 256), packRange);
  // The scene's kinematic frame (readEnergy, clampFrameVelocity): only a translating kinematic
  // body gives a frame without rotation (a scripted spin is in its L), and only one is a frame.
  kinematicFrameBody_ = -1;
  int kinematicCount = 0;
  for (std::size_t i = 0; i < bodies.size(); ++i)
    if (bodies[i].kinematic) kinematicFrameBody_ = static_cast<int>(i), ++kinematicCount;
  if (kinematicCount != 1 || bodies[kinematicFrameBody_].omega().squaredNorm() != 0) kinematicFrameBody_ = -1;
  return !bodies.empty();
}

template <int d>
typename ContactWorkspace<d>::VecD ContactWorkspace<d>::clampFrameVelocity(const ContactBody<d>& partner,
                                                                           const VecD& r) const {
  // An impulse against a body of infinite mass changes only the other body's energy. Against a
  // kinematic body it is measured in that body's frame (its script does the work: the elevator),
  // against a static one in the world. A frozen body (shock propagation) is a dynamic body
  // that takes no impulse: in its own frame, a frozen body moving up could push the body above
  // it up and add energy that nothing pays for (random scenes gained up to 46 % of their
  // kinetic energy in Step V that way), so it is measured in the world, or the kinematic
  // frame of the scene, as the stage's energy is checked.
  if (partner.kinematic) return partner.pointVelocity(r);
  if (partner.still() || kinematicFrameBody_ < 0) return VecD::Zero();
  return bodies[kinematicFrameBody_].v;
}

template <int d>
void ContactWorkspace<d>::reloadVelocities() {
  for (ContactBody<d>& b : bodies) {
    if (b.immovable()) continue;
    b.v = b.body->v;
    b.L = b.body->L;
  }
}

template <int d>
void ContactWorkspace<d>::unpack(bool positions) {
  for (ContactBody<d>& b : bodies) {
    if (b.immovable()) continue;
    b.body->v = b.v;
    b.body->L = b.L;
    if (positions) {
      b.body->x = b.x0;
      b.body->orientation = b.q0;
    }
  }
}

template <int d>
typename ContactWorkspace<d>::EnergyReading ContactWorkspace<d>::readEnergy() const {
  EnergyReading r;
  for (const auto& b : bodies) r.world += b.kineticEnergy();
  r.hasKinematicFrame = kinematicFrameBody_ >= 0;
  if (r.hasKinematicFrame) {
    const VecD frame = bodies[kinematicFrameBody_].v;
    for (const auto& b : bodies)
      if (!b.infinite()) r.kinematicFrame += 0.5 * b.mass * (b.v - frame).squaredNorm() + 0.5 * b.L.dot(b.omega());
  }
  return r;
}

template <int d>
void ContactWorkspace<d>::reportEnergyChange(DiagnosticsSink& out, const std::string& name, const EnergyReading& before,
                                             const EnergyReading& after) {
  // Relative to the energy before (absolute when that is ~0).
  out.set(name, (after.world - before.world) / std::max(before.world, 1e-12));
  out.set(name + "_absolute", after.world - before.world);
  if (before.hasKinematicFrame && after.hasKinematicFrame)
    out.set(name + "_kinematic_frame",
            (after.kinematicFrame - before.kinematicFrame) / std::max(before.kinematicFrame, 1e-12));
}

template <int d>
void ContactWorkspace<d>::updateCandidate(ContactBody<d>& b, const CandidateStep& step) {
  if (b.still()) {
    b.candidate.x = b.x0;
    b.candidate.R = b.R0;
    b.inverseInertiaCandidate = b.inverseInertia0;
    return;
  }
  const double dt = step.dt, k = step.kick ? 1.0 : 0.0;
  b.candidate.x = b.x0 + dt * (b.v + k * b.dv);
  if (b.turnFree) {
    b.candidate.R = b.R0;
    b.inverseInertiaCandidate = b.body->inertiaBodyInverse;  // c I, the same in every frame
    return;
  }
  const con::AngVec<d> w = b.inverseInertia0 * (b.L + k * b.dL);
  b.candidate.R = rotationOf<d>(rotatedBy<d>(b.q0, dt * w));
  if constexpr (d == 3) b.inverseInertiaCandidate = b.candidate.R * b.body->inertiaBodyInverse * b.candidate.R.transpose();
  else b.inverseInertiaCandidate = b.inverseInertia0;
}

template <int d>
col::StepMotion<d> ContactWorkspace<d>::stepMotion(const ContactBody<d>& b, const CandidateStep& step) {
  col::StepMotion<d> m;
  m.start.x = b.x0;
  m.start.R = b.R0;
  if (b.still()) return m;
  const double k = step.kick ? 1.0 : 0.0;
  m.translation = b.candidate.x - b.x0;
  const con::AngVec<d> w = b.inverseInertia0 * (b.L + k * b.dL);  // as updateCandidate turns it
  m.rotation = step.dt * w;
  return m;
}

template <int d>
void ContactWorkspace<d>::updateAllCandidates(const CandidateStep& step) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, bodies.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) updateCandidate(bodies[i], step);
  });
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
    infinite_[i] = b.immovable() ? 1 : 0;
  }
  // Sweep and prune is the faster of the two below about 500 boxes, FCL's dynamic AABB tree
  // above (bench_narrow_phase); both return the same sorted pairs.
  if (!broadPhase_)
    broadPhase_ = std::make_unique<col::BroadPhase<d>>(n > 500 ? col::BroadPhaseMethod::FclDynamicTree
                                                               : col::BroadPhaseMethod::SweepAndPrune);
  broadPhase_->excludePairs(jointedPairs_);
  const auto& found = broadPhase_->findPairs(boxes_, infinite_);
  // A fresh state per pair, how its last manifold solve ended included: nothing of the
  // workspace outlives the step, so a run resumed from a checkpoint (which holds only the
  // components) continues bitwise as the uninterrupted one.
  std::vector<ContactPairState>& fresh = freshPairs_;
  fresh.assign(found.size(), ContactPairState{});
  for (std::size_t k = 0; k < found.size(); ++k) {
    fresh[k].a = found[k].first;
    fresh[k].b = found[k].second;
    fresh[k].manifold = static_cast<int>(k);
  }
  pairs.swap(fresh);
  resetManifolds(found.size());
  con::computeIslands(n, found, infinite_, islands);
  islandPairsByLevel = islands.pairs;
  tasks_.setIslands(islands, infinite_);
}

template <int d>
col::Pose<d> ContactWorkspace<d>::reAdvanced(const ContactBody<d>& b, double dt, double k) {
  col::Pose<d> p;
  if (b.still()) {
    p.x = b.x0;
    p.R = b.R0;
    return p;
  }
  p.x = b.x0 + dt * (b.v + k * b.dv);
  p.R = b.turnFree ? b.R0 : rotationOf<d>(rotatedBy<d>(b.q0, dt * (b.inverseInertia0 * (b.L + k * b.dL))));
  return p;
}

template <int d>
void ContactWorkspace<d>::rebuildPairsFrom(const std::vector<std::pair<int, int>>& found) {
  // `found` is sorted and contains every known pair (the boxes only grew): walk both lists for
  // where each pair comes from (a known pair's index, or -1 for a new one), then fill the new
  // list at once, each pair in its own slot (the states are large: copying them one after
  // another was a quarter of a pour's rebuild, the islands and level lists the rest), and give
  // the new pairs their manifold slots in order.
  // This thread's buffers, by reference: the workers below must write into these, not their own.
  thread_local std::vector<int> sourceBuffer;
  thread_local std::vector<ContactPairState> mergedBuffer;
  std::vector<int>& source = sourceBuffer;
  std::vector<ContactPairState>& merged = mergedBuffer;
  source.resize(found.size());
  std::size_t old = 0;
  for (std::size_t k = 0; k < found.size(); ++k) {
    const bool known = old < pairs.size() && pairs[old].a == found[k].first && pairs[old].b == found[k].second;
    source[k] = known ? static_cast<int>(old++) : -1;
  }
  if (old != pairs.size()) throw std::logic_error("ContactWorkspace: a grown broad phase lost a pair");
  merged.resize(found.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, found.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k) {
      if (source[k] >= 0) {
        merged[k] = pairs[source[k]];
        continue;
      }
      merged[k] = ContactPairState{};
      merged[k].a = found[k].first;
      merged[k].b = found[k].second;
      merged[k].level = levels.levelOf.empty() ? 0 : std::max(levels.levelOf[merged[k].a], levels.levelOf[merged[k].b]);
    }
  });
  for (std::size_t k = 0; k < found.size(); ++k) {
    if (source[k] >= 0) continue;
    merged[k].manifold = static_cast<int>(manifolds_.size());
    manifolds_.emplace_back();
  }
  pairs.swap(merged);
  const int n = static_cast<int>(bodies.size());
  con::computeIslands(n, found, infinite_, islands);
  tasks_.setIslands(islands, infinite_);
  sortIslandPairsByLevel();
}

template <int d>
void ContactWorkspace<d>::resetManifolds(std::size_t pairCount) {
  // The slots' storage is kept from step to step (no allocation per step); their contents not.
  manifolds_.resize(pairCount);
  for (CachedManifold& m : manifolds_) m.valid = false;
}

namespace {

// Shapes whose contact normal is a face normal or an edge-edge cross product of a convex
// polytope (or a half-space's normal): carried along with the bodies, such a normal and the
// touching features stay those of a fresh query for small relative motions. A round shape's
// normal follows the other body's point around it, so spheres, capsules and cylinders are always
// queried afresh (their queries are closed forms or short searches anyway), and so are meshes,
// whose faces meet at any angle: a point carried across an edge of a mesh would keep the plane
// of the triangle it left.
template <int d>
bool carriesFeatures(const col::PreparedGeometry<d>& g) {
  const col::GeometryType t = g.geometry().type;
  return t == col::GeometryType::Box || t == col::GeometryType::Convex || t == col::GeometryType::HalfSpace;
}

// How far, as a fraction of the smaller body's bounding radius, the smaller body may move in the
// larger one's frame before the pair is queried again. The points are found with the contact
// margin plus this reach, so no feature within the margin at the new pose is missed. Measured on
// pyramid_20: a pair's relative pose moves 2-9 mm (about 1 % of a box's radius) between the
// contact stages of a step, as each stage's impulses change the candidate velocities.
constexpr double kManifoldReach = 0.02;

}  // namespace

// A pair whose smaller body moved by at most m in the larger one's frame (m = |dx| + |dR| r)
// since its manifold was found keeps that manifold's points, carried with the bodies: each
// point's witness points move with their bodies and its normal with the body whose face it is (a
// half-space's, else B's, the level-set body's of the thesis's convention); the depth is the
// witness points' distance along the normal, the point their midpoint. For a vertex against a
// face of the normal's owner this is exact; otherwise the depth is off by at most the witness
// points' tangential drift times the normal's relative turn, at most m |dR|, which is held within
// push-out's tolerance (the overlap push-out leaves alone). A feature that comes within the margin
// at the new pose is among the points, which were found with the margin plus the reach. What the
// carried points do not follow: a point whose support moves from under it (a corner sliding over
// the edge of the face it rests on, or a clipped corner of a face contact that is a material
// point of neither body, an overhang's edge crossing) stays where the witness points put it, off
// by at most m / 2 along the face, until the next step's query.
template <int d>
int ContactWorkspace<d>::pairContacts(const ContactPairState& pair, bool firstIsB, const ContactBody<d>& first,
                                      const ContactBody<d>& second, const col::ContactQuery& query,
                                      std::vector<col::ContactPoint<d>>& out) const {
  const ContactBody<d>& A = firstIsB ? second : first;
  const ContactBody<d>& B = firstIsB ? first : second;
  const bool cacheable = pair.manifold >= 0 && pair.manifold < static_cast<int>(manifolds_.size()) &&
                         carriesFeatures<d>(*A.geometry) && carriesFeatures<d>(*B.geometry);
  if (!cacheable) return col::findContacts(*first.geometry, first.candidate, *second.geometry, second.candidate, query, out);
  const col::Pose<d>& pa = A.candidate;
  const col::Pose<d>& pb = B.candidate;
  // The smaller body moves in the larger one's frame (a half-space's radius is infinite).
  const bool aMoves = A.geometry->boundingRadius() <= B.geometry->boundingRadius();
  const col::Pose<d>& mover = aMoves ? pa : pb;
  const col::Pose<d>& base = aMoves ? pb : pa;
  const double radius = std::min(A.geometry->boundingRadius(), B.geometry->boundingRadius());
  const Eigen::Matrix<double, d, d> relativeR = base.R.transpose() * mover.R;
  const VecD relativeX = base.R.transpose() * (mover.x - base.x);
  CachedManifold& cached = manifolds_[pair.manifold];
  const double sign = firstIsB ? -1.0 : 1.0;  // normals out of `second`
  if (cached.valid && cached.margin == query.margin) {
    const double turn = (relativeR - cached.relativeR).norm();
    const double moved = (relativeX - cached.relativeX).norm() + turn * radius;
    if (moved <= cached.reach && moved * turn <= settings.pushOutTolerance) {
      int count = 0;
      for (const CachedPoint& c : cached.points) {
        const VecD onA = pa.x + pa.R * c.onA, onB = pb.x + pb.R * c.onB;
        const VecD n = (c.normalOnA ? pa.R : pb.R) * c.normal;
        const double depth = (onB - onA).dot(n);
        if (depth < -query.margin) continue;
        col::ContactPoint<d>& p = out.emplace_back();
        p.point = 0.5 * (onA + onB);
        p.normal = sign * n;
        p.depth = depth;
        ++count;
      }
      return count;
    }
  }
  col::ContactQuery wide = query;
  const double reach = kManifoldReach * radius;
  wide.margin = query.margin + reach;
  const std::size_t begin = out.size();
  col::findContacts(*A.geometry, pa, *B.geometry, pb, wide, out);
  cached.valid = true;
  cached.margin = query.margin;
  cached.reach = reach;
  cached.relativeR = relativeR;
  cached.relativeX = relativeX;
  cached.points.clear();
  const bool normalOnA = A.geometry->geometry().type == col::GeometryType::HalfSpace;
  std::size_t kept = begin;
  for (std::size_t k = begin; k < out.size(); ++k) {
    const col::ContactPoint<d> p = out[k];
    CachedPoint& c = cached.points.emplace_back();
    c.onA = pa.R.transpose() * (p.pointOnA() - pa.x);
    c.onB = pb.R.transpose() * (p.pointOnB() - pb.x);
    c.normalOnA = normalOnA;
    c.normal = (normalOnA ? pa.R : pb.R).transpose() * p.normal;
    if (p.depth < -query.margin) continue;  // only carried: beyond the margin here
    out[kept] = p;
    out[kept].normal = sign * p.normal;
    ++kept;
  }
  out.resize(kept);
  return static_cast<int>(kept - begin);
}

template <int d>
void ContactWorkspace<d>::sortIslandPairsByLevel() {
  // Each island's list in its own slot (the islands at once), sorted by counting levels.
  islandPairsByLevel.resize(islands.pairs.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, islands.pairs.size(), 16), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      auto& list = islandPairsByLevel[i];
      list.clear();
      for (int p : islands.pairs[i])
        if (pairs[p].processed) list.push_back(p);
      con::stableSortByKey(list, [&](int p) { return pairs[p].level; });
    }
  });
}

template <int d>
int ContactWorkspace<d>::computeLevels(double dt) {
  // "a below b" when b, re-advanced with its new velocity (with the Step I kick), overlaps a
  // advanced with its old one (notes 1.6). Bodies of infinite mass are never re-advanced, so
  // they end up at the bottom.
  std::vector<std::pair<int, int>>& edges = graphEdges;
  edges.clear();
  // Each body's two poses once (a quaternion turn each), read by every pair it is in.
  std::vector<std::array<col::Pose<d>, 2>>& poses = reAdvancedPoses_;
  poses.resize(bodies.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, bodies.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i)
      poses[i] = {reAdvanced(bodies[i], dt, 0.0), reAdvanced(bodies[i], dt, 1.0)};
  });
  const int added = growPairs([&](const ContactBody<d>& b) -> const std::array<col::Pose<d>, 2>& { return poses[&b - bodies.data()]; });
  // The same test also completes the processed list (notes 1.4, "contact pairs" gathered on the
  // last collision sweep): bodies resting on each other fall together in the candidate
  // positions, so only moving one of them with its new velocity shows that they touch. A
  // separation within the contact thickness counts as touching.
  auto touches = [&](int mover, int other) {
    return col::touches(*bodies[mover].geometry, poses[mover][1], *bodies[other].geometry, poses[other][0],
                        settings.thickness);
  };
  // The tests only read the bodies: each pair's two answers in its own slot, in parallel, then
  // the edges in pair order (the same list on any thread count).
  std::vector<char> aOverB(pairs.size(), 0), bOverA(pairs.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pairs.size(), 64), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k) {
      const ContactBody<d>& A = bodies[pairs[k].a];
      const ContactBody<d>& B = bodies[pairs[k].b];
      aOverB[k] = !A.immovable() && touches(pairs[k].a, pairs[k].b);
      bOverA[k] = !B.immovable() && touches(pairs[k].b, pairs[k].a);
    }
  });
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    ContactPairState& pair = pairs[k];
    if (aOverB[k]) edges.emplace_back(pair.b, pair.a);
    if (bOverA[k]) edges.emplace_back(pair.a, pair.b);
    if (aOverB[k] || bOverA[k]) pair.processed = true;
  }
  con::computeLevels(static_cast<int>(bodies.size()), edges, levels);
  for (ContactPairState& pair : pairs) pair.level = std::max(levels.levelOf[pair.a], levels.levelOf[pair.b]);
  sortIslandPairsByLevel();
  return added;
}

template <int d>
typename ContactWorkspace<d>::PairImpulse ContactWorkspace<d>::findPairImpulse(
    ContactPairState& pair, const ContactBody<d>& A, const ContactBody<d>& B, ImpulseMode mode,
    const CandidateStep& step, double epsilon, int iterations, double margin,
    std::vector<col::ContactPoint<d>>& scratch, double* clampEnergyChange, int* clampsApplied,
    bool shockFriction) const {
  if (A.infinite() && B.infinite()) return {};
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
  // Where the pair is tested: the candidate poses (GBF 2003), or, for a collision of bodies
  // that move more than half the thinner one's size in the step, where they first touch along
  // the motion (swept_contact.h), with the split inertia turned to that pose.
  col::Pose<d> poseA = A.candidate, poseB = B.candidate;
  con::AngMat<d> splitA = A.inverseInertiaCandidate, splitB = B.inverseInertiaCandidate;
  col::ContactQuery query;
  query.margin = margin;
  scratch.clear();
  bool swept = false;
  if (collision && settings.sweptCollisions) {
    const col::StepMotion<d> ma = stepMotion(A, step), mb = stepMotion(B, step);
    const double size = std::min(col::tunnelingSize(*A.geometry), col::tunnelingSize(*B.geometry));
    swept = col::relativeTravel(*A.geometry, ma, *B.geometry, mb) > 0.5 * size;
    if (swept) {
      col::SweptQuery first;
      first.sampleTravel = 0.5 * size;
      const double s = col::firstContactFraction(*A.geometry, ma, *B.geometry, mb, first);
      if (s < 0) return {};
      pair.swept = true;
      poseA = ma.at(s);
      poseB = mb.at(s);
      splitA = splitInverseInertiaAt(A, poseA);
      splitB = splitInverseInertiaAt(B, poseB);
      // The bisection leaves the bodies barely overlapping: report the face's other corners too.
      query.margin = std::max(margin, 1e-3 * size);
    }
  }
  if (!swept && !mayTouch<d>(A, B, margin)) return {};
  if (collision && !swept && !mayApproach<d>(A, B, splitA, splitB, margin, settings.approachTolerance)) {
    // No point of the pair can approach: no impulse whatever the manifold. Only whether the
    // pair touches is kept (the processed list, notes 1.4): the same answer without the points.
    if (col::touches(*A.geometry, poseA, *B.geometry, poseB, query.margin)) pair.processed = true;
    return {};
  }
  // Collisions meet each pair at poses of their own (time-n velocities, swept): a fresh narrow
  // phase; the contact stages share the pair's manifold (pairContacts).
  const int found = collision ? col::findContacts(*A.geometry, poseA, *B.geometry, poseB, query, scratch)
                              : pairContacts(pair, false, A, B, query, scratch);
  if (found == 0) return {};
  if (collision) pair.processed = true;
  // Manifold points within the margin, with split-state lever arms and normals (candidate
  // positions, as GBF 2003 and Sec. 2.3.2 compute them; mapping points back through the body's
  // rotation to time n, as the level-set code does for surface vertices, is wrong for round
  // shapes: a rolling disk's deepest point is not a material point).
  const bool finiteA = !A.infinite(), finiteB = !B.infinite();
  con::PgsBodies<d> state;
  state.va = A.v;
  state.vb = B.v;
  state.wa = splitA * A.L;
  state.wb = splitB * B.L;
  state.inverseMassA = A.inverseMass();
  state.inverseMassB = B.inverseMass();
  state.movesA = finiteA;  // bodies of infinite mass take no impulse
  state.movesB = finiteB;
  const double allowance = shockFriction && !collision ? stageAllowance(pair, impulse.friction) : 0.0;
  // Collisions keep the thesis's test (no gaps closed): they meet the time-n velocity, not the
  // one the candidates moved with, and a body they stop above a gap falls through it in contact.
  con::ManifoldProblem<d>& problem = threadProblem<d>();
  problem.start(con::ManifoldProblem<d>::Shape::Pair, state,
                targetsOf(settings, step.dt, impulse.restitution, settings.closeGaps && !collision));
  for (const auto& c : scratch) {
    if (c.depth < -query.margin) continue;
    problem.add(VecD(c.point - poseA.x), VecD(c.point - poseB.x), c.normal, VecD::Zero(), c.depth, impulse.friction,
                allowance > 0);
  }
  if (!problem.needsSolve()) return {};
  problem.setLeaning(0, allowance);
  // The rows only when something approaches or slides (a solve follows).
  const con::AngMat<d> Ia = finiteA ? splitA : con::AngMat<d>::Zero();
  const con::AngMat<d> Ib = finiteB ? splitB : con::AngMat<d>::Zero();
  problem.solve(A.inverseMass() + B.inverseMass(), Ia, Ib, settings.exactManifoldFinish, iterations, &impulse,
                &pair.end);
  // Net impulse on A and its angular impulse about A's centre.
  VecD J;
  con::AngVec<d> tau;
  const int active = problem.netImpulse(J, tau);
  if (active == 0) return {};
  const auto& points = problem.points();
  double scale = 1;
  if (clamp) {
    // Energy of the non-split base state; a partner of infinite mass that moves (kinematic)
    // is handled in its frame: the dynamic body's velocity relative to its point velocity.
    // The pair's impulse is J at A's centre plus the torque tau (and -J, -tau - (x_a - x_b) x J on B).
    const VecD rb = poseA.x - poseB.x;
    con::ClampBody<d> ca{A.inverseMass(), A.inverseInertia(), A.v, A.L, VecD::Zero()};
    con::ClampBody<d> cb{B.inverseMass(), B.inverseInertia(), B.v, B.L, rb};
    const VecD centre = points[0].ra;  // frame point for a kinematic partner's velocity
    if (B.infinite()) ca.velocity = A.v - clampFrameVelocity(B, points[0].rb), cb.velocity.setZero(), cb.angularMomentum.setZero();
    if (A.infinite()) cb.velocity = B.v - clampFrameVelocity(A, centre), ca.velocity.setZero(), ca.angularMomentum.setZero();
    const con::ClampResult r = con::clampImpulseEnergy<d>(ca, cb, J, tau);
    if (r.kind != con::ClampResult::Case::NoGain && clampsApplied) ++*clampsApplied;
    if (clampEnergyChange) *clampEnergyChange += r.energyChange;
    scale = r.scale;
    if (scale == 0) return {};
  }
  if (!collision) addToStage<d>(pair, points.data(), points.data() + points.size(), scale, 1.0);
  return {active, J, tau, scale, VecD(poseA.x - poseB.x)};
}

template <int d>
void ContactWorkspace<d>::applyPairImpulse(ContactPairState& pair, ContactBody<d>& A, ContactBody<d>& B,
                                           const PairImpulse& r, ImpulseMode mode,
                                           const CandidateStep& step) const {
  if (!A.infinite()) {
    A.v += r.scale * A.inverseMass() * r.J;
    A.L += r.scale * r.tau;
    updateCandidate(A, step);
  }
  if (!B.infinite()) {
    B.v -= r.scale * B.inverseMass() * r.J;
    B.L -= r.scale * (r.tau + con::cross<d>(r.fromB, r.J));
    updateCandidate(B, step);
  }
  if (mode != ImpulseMode::Collision) pair.contacted = true;
}

template <int d>
int ContactWorkspace<d>::updateBodyAgainstFrozen(int c, const int* pairList, int count, ImpulseMode mode,
                                                 const CandidateStep& step, double epsilon, int iterations,
                                                 double margin,
                                                 std::vector<col::ContactPoint<d>>& scratch,
                                                 double* clampEnergyChange, int* clampsApplied) {
  // Shock propagation with a body resting on several bodies of lower levels (a pyramid box on
  // the two below it): the lower bodies are frozen, so the body's contacts with all of them form
  // one small problem for this body alone, solved jointly by projected Gauss-Seidel. Solving
  // them pair after pair instead leaves a residual slip that shows as a slow creep.
  ContactBody<d>& C = bodies[c];
  if (C.infinite()) return 0;
  col::ContactQuery query;
  query.margin = margin;
  con::PgsBodies<d> state;  // C is body a; the partners are frozen (their velocity per point)
  state.va = C.v;
  state.wa = C.inverseInertiaCandidate * C.L;
  state.inverseMassA = C.inverseMass();
  state.movesA = true;
  con::ManifoldProblem<d>& problem = threadProblem<d>();
  problem.start(con::ManifoldProblem<d>::Shape::AgainstFrozen, state,
                targetsOf(settings, step.dt, -1.0 + epsilon, settings.closeGaps));
  VecD frameVelocity = VecD::Zero();
  bool frameSet = false, frameKinematic = false;
  // Each pair's points, [pointsEnd[q-1], pointsEnd[q]): their friction leans on what that pair
  // carried earlier in the stage, and their impulses are added to it (findPairImpulse,
  // "shockFriction": this solve only runs in shock propagation).
  thread_local std::vector<int> pointsEnd;
  pointsEnd.assign(count, 0);
  for (int q = 0; q < count; ++q) {
    ContactPairState& pair = pairs[pairList[q]];
    const bool cIsA = pair.a == c;
    const ContactBody<d>& P = bodies[cIsA ? pair.b : pair.a];
    scratch.clear();
    const std::size_t first = problem.size();
    pointsEnd[q] = static_cast<int>(first);
    if (!mayTouch<d>(C, P, margin)) continue;
    if (pairContacts(pair, !cIsA, C, P, query, scratch) == 0) continue;
    const double mu = std::min(C.friction, P.friction);
    const double allowance = stageAllowance(pair, mu);
    const con::AngVec<d> partnerSpin = P.inverseInertiaCandidate * P.L;
    for (const auto& cp : scratch) {
      if (cp.depth < -margin) continue;
      const VecD fromP = cp.point - P.candidate.x;
      // The clamp's frame (clampFrameVelocity): a kinematic partner's if there is one.
      if (!frameSet || (P.kinematic && !frameKinematic)) {
        frameVelocity = clampFrameVelocity(P, fromP);
        frameSet = true;
        frameKinematic = P.kinematic;
      }
      // The normal out of P towards C: C is "A" in pairContacts above.
      problem.add(VecD(cp.point - C.candidate.x), VecD::Zero(), cp.normal,
                  VecD(P.v + con::spinVelocity<d>(partnerSpin, fromP)), cp.depth, mu, allowance > 0);
    }
    problem.setLeaning(first, allowance);
    pointsEnd[q] = static_cast<int>(problem.size());
    if (mode != ImpulseMode::Collision) pair.contacted = true;
  }
  if (!problem.needsSolve()) return 0;
  // The plain solve first; as in findPairImpulse, solved again leaning on the stage where it
  // leaves a slip.
  problem.solve(C.inverseMass(), C.inverseInertiaCandidate, con::AngMat<d>::Zero(), settings.exactManifoldFinish,
                iterations, nullptr, nullptr);
  VecD J;
  con::AngVec<d> tau;
  const int active = problem.netImpulse(J, tau);
  if (active == 0) return 0;
  const auto& points = problem.points();
  double scale = 1;
  if (settings.energyClamp && mode == ImpulseMode::ClampedContact) {
    // The partners have infinite mass here; energy is measured in the frame clampFrameVelocity
    // gives the first partner (a kinematic partner's, if any).
    con::ClampBody<d> cc{C.inverseMass(), C.inverseInertia(), VecD(C.v - frameVelocity), C.L, VecD::Zero()};
    con::ClampBody<d> partner;
    const con::ClampResult r = con::clampImpulseEnergy<d>(cc, partner, J, tau);
    if (r.kind != con::ClampResult::Case::NoGain && clampsApplied) ++*clampsApplied;
    if (clampEnergyChange) *clampEnergyChange += r.energyChange;
    scale = r.scale;
    if (scale == 0) return 0;
  }
  for (int q = 0, begin = 0; q < count; begin = pointsEnd[q++]) {
    ContactPairState& pair = pairs[pairList[q]];
    addToStage<d>(pair, points.data() + begin, points.data() + pointsEnd[q], scale, pair.a == c ? 1.0 : -1.0);
  }
  C.v += scale * C.inverseMass() * J;
  C.L += scale * tau;
  updateCandidate(C, step);
  return active;
}

template <int d>
int ContactWorkspace<d>::taskGrain() const {
  // Blocks of 4 updates: measured on 2 threads (docs/benchmarks.md) against 1, 2, 8 and 16, it
  // keeps pyramid_20's speed-up and stops the cheap sphere-pair checks of a pour from costing
  // more to hand over than to run. With the exact finish most manifold solves end before their
  // first sweep, so an update costs less and blocks of 2 hand over better: on 2 threads the
  // short-schedule pyramid_20 step took 17 % less time with 2 than with 4 (16: 19 % more),
  // while at the defaults and in the 250-sphere pour 2 cost 2-5 % more (the git history of docs/benchmarks.md
  // ("Exact finish before the first sweep")).
  return settings.exactManifoldFinish ? 2 : 4;
}

// What a collision check leaves for the skip test (notes 1.4): the bodies it moved carry its
// stamp, the pair the one after it.
template <int d>
void markCollisionChecked(ContactPairState& pair, ContactBody<d>& A, ContactBody<d>& B, long stamp, bool moved) {
  if (moved) {
    if (!A.infinite()) A.movedStamp = stamp;
    if (!B.infinite()) B.movedStamp = stamp;
  }
  pair.checkedStamp = stamp + 1;
}

template <int d>
TaskCounts ContactWorkspace<d>::runTask(const SweepTask& t, ImpulseMode mode, const CandidateStep& step,
                                        const std::vector<int>& lists) {
  thread_local std::vector<col::ContactPoint<d>> scratch;  // per worker thread
  TaskCounts c;
  switch (t.kind) {
    case SweepTask::Kind::Collision: {
      ContactPairState& pair = pairs[t.index];
      ContactBody<d>& A = bodies[pair.a];
      ContactBody<d>& B = bodies[pair.b];
      // Checked after both bodies last moved: nothing new to find (notes 1.4).
      if (pair.checkedStamp > std::max(A.movedStamp, B.movedStamp)) return c;
      c.impulses = updatePair(pair, ImpulseMode::Collision, step, 0.0, t.iterations, 0.0, scratch, &c.energyChange,
                              &c.clamps);
      markCollisionChecked(pair, A, B, t.stamp, c.impulses > 0);
      break;
    }
    case SweepTask::Kind::Pair:
      c.impulses = updatePair(pairs[t.index], mode, step, t.epsilon, t.iterations, settings.thickness, scratch,
                              &c.energyChange, &c.clamps, t.shockFriction);
      break;
    case SweepTask::Kind::Joint:
      c.impulses = updateBodyAgainstFrozen(t.index, lists.data() + t.listBegin, t.listEnd - t.listBegin, mode,
                                           step, t.epsilon, t.iterations, settings.thickness, scratch, &c.energyChange,
                                           &c.clamps);
      break;
    case SweepTask::Kind::Freeze:
      bodies[t.index].frozen = true;
      break;
  }
  return c;
}

template <int d>
void ContactWorkspace<d>::addTask(Sequence& s, ImpulseMode mode, const CandidateStep& step, const SweepTask& task,
                                  const int* touched, int count) {
  tasks_.add(s, task, touched, count, [&](const SweepTask& t) { return runTask(t, mode, step, s.lists); });
}

template <int d>
int ContactWorkspace<d>::runTasks(Sequence& s, ImpulseMode mode, const CandidateStep& step) {
  return tasks_.run(s, [&](const SweepTask& t) { return runTask(t, mode, step, s.lists); });
}

// Stamps that grow along the whole sequence of checks, sweep after sweep: "moved" gets the
// even stamp of the check that moved the body, "checked" the odd one after it, both above the
// initial values (moved 0, checked -1), so the skip test compares the order of events.
inline long collisionStamp(int sweep, std::size_t pairCount, std::size_t k) {
  return 2 * (static_cast<long>(sweep) * static_cast<long>(pairCount) + static_cast<long>(k) + 1);
}

template <int d>
int ContactWorkspace<d>::runCollisionTasks(Sequence& s, int island, int sweep, const CandidateStep& step,
                                           std::size_t from) {
  const auto& list = islands.pairs[island];
  for (std::size_t k = from; k < list.size(); ++k) {
    SweepTask t;
    t.kind = SweepTask::Kind::Collision;
    t.index = list[k];
    t.iterations = settings.collisionPairIterations;
    t.stamp = collisionStamp(sweep, list.size(), k);
    const int touched[2] = {pairs[t.index].a, pairs[t.index].b};
    addTask(s, ImpulseMode::Collision, step, t, touched, 2);
  }
  return runTasks(s, ImpulseMode::Collision, step);
}

template <int d>
int ContactWorkspace<d>::collisionSweep(int island, int sweep, const CandidateStep& step, double* clampEnergyChange,
                                        int* clampsApplied) {
  const auto& list = islands.pairs[island];
  auto stamp = [&](std::size_t k) { return collisionStamp(sweep, list.size(), k); };
  Sequence& again = tasks_.sequence(island);
  if (sweep > 0 && again.reusable && again.tasks.size() == list.size()) {
    // The previous sweep's tasks and dependencies, with this sweep's stamps (recording them
    // again cost about what the second thread saved in a pour's settled pile).
    for (std::size_t k = 0; k < list.size(); ++k) again.tasks[k].stamp = stamp(k);
    again.energyOut = clampEnergyChange;
    again.clampsOut = clampsApplied;
    return runTasks(again, ImpulseMode::Collision, step);
  }
  if (sweep == 0 && lastCollisionImpulses == 0 && list.size() >= 64 && tbb::this_task_arena::max_concurrency() > 1)
    return speculativeCollisionSweep(island, step, clampEnergyChange, clampsApplied);
  Sequence& s = tasks_.start(island, list.size(), taskGrain(), clampEnergyChange, clampsApplied);
  s.reusable = s.order.tracking();  // later sweeps of the step reuse the tasks
  return runCollisionTasks(s, island, sweep, step, 0);
}

template <int d>
int ContactWorkspace<d>::speculativeCollisionSweep(int island, const CandidateStep& step, double* clampEnergyChange,
                                                   int* clampsApplied) {
  const auto& list = islands.pairs[island];
  const std::size_t n = list.size();
  auto stamp = [n](std::size_t k) { return collisionStamp(0, n, k); };
  // 1. Every update at once, applying nothing (the first sweep checks every pair: none skips).
  probes_.assign(n, CollisionProbe{});
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16), [&](const tbb::blocked_range<std::size_t>& r) {
    thread_local std::vector<col::ContactPoint<d>> scratch;
    for (std::size_t k = r.begin(); k != r.end(); ++k) {
      CollisionProbe& probe = probes_[k];
      probe.pair = pairs[list[k]];
      probe.impulses = findPairImpulse(probe.pair, bodies[probe.pair.a], bodies[probe.pair.b], ImpulseMode::Collision,
                                       step, 0.0, settings.collisionPairIterations, 0.0, scratch, &probe.energyChange,
                                       &probe.clamps)
                           .active;
    }
  });
  // 2. In order, up to the first update with impulses to apply (runTask's bookkeeping).
  std::size_t k = 0;
  for (; k < n && probes_[k].impulses == 0; ++k) {
    const CollisionProbe& probe = probes_[k];
    ContactPairState& pair = pairs[list[k]];
    pair = probe.pair;
    markCollisionChecked(pair, bodies[pair.a], bodies[pair.b], stamp(k), false);
    addTaskCounts({0, probe.clamps, probe.energyChange}, nullptr, clampsApplied, clampEnergyChange);
  }
  if (k == n) return 0;
  // 3. The rest as the ordered sweep runs them (recorded afresh; later sweeps record their own).
  Sequence& s = tasks_.start(island, n - k, taskGrain(), clampEnergyChange, clampsApplied);
  return runCollisionTasks(s, island, 0, step, k);
}

template <int d>
int ContactWorkspace<d>::contactSweeps(int island, ImpulseMode mode, const CandidateStep& step, bool onlyContacted,
                                       double* clampEnergyChange, int* clampsApplied) {
  const auto& list = islandPairsByLevel[island];
  const int iterations = settings.contactIterations, levelIterations = settings.contactLevelIterations;
  // A new stage (Step III's contact, or Step V's): its impulses are summed from here on.
  for (int k : list) {
    pairs[k].stageNormal = 0;
    pairs[k].stageFriction = {0, 0, 0};
  }
  Sequence& s =
      tasks_.start(island, list.size() * iterations * levelIterations, taskGrain(), clampEnergyChange, clampsApplied);
  for (int it = 0; it < iterations; ++it) {
    for (std::size_t begin = 0; begin < list.size();) {
      std::size_t end = begin;
      while (end < list.size() && pairs[list[end]].level == pairs[list[begin]].level) ++end;
      for (int li = 0; li < levelIterations; ++li) {
        const double eps = double((it + 1) * (li + 1)) / double(iterations * levelIterations);
        for (std::size_t k = begin; k < end; ++k) {
          const ContactPairState& pair = pairs[list[k]];
          // Step V's pairs: those Step III touched (fixed during the sweeps: a pair update only
          // ever sets the flag on a pair that already has it here).
          if (onlyContacted && !pair.contacted) continue;
          SweepTask t;
          t.kind = SweepTask::Kind::Pair;
          t.index = list[k];
          t.epsilon = eps;
          t.iterations = settings.contactPairIterations;
          const int touched[2] = {pair.a, pair.b};
          addTask(s, mode, step, t, touched, 2);
        }
      }
      begin = end;
    }
  }
  return runTasks(s, mode, step);
}

template <int d>
int ContactWorkspace<d>::propagateShock(int island, ImpulseMode mode, const CandidateStep& step, bool onlyContacted,
                                        double* clampEnergyChange, int* clampsApplied) {
  const auto& list = islandPairsByLevel[island];
  // At most one task per pair and level iteration, and one freeze per body.
  Sequence& s = tasks_.start(island, list.size() * settings.shockLevelIterations + islands.members[island].size(),
                             taskGrain(), clampEnergyChange, clampsApplied);
  // Per level, what each of its pairs does in every level iteration (the level's pairs and which
  // bodies are frozen do not change during them): a joint solve of the upper body against its
  // partners of infinite mass, at the first of its pairs with such a partner; nothing, for the
  // other pairs that joint solve covers; else a pair update. Found by grouping the pairs by
  // upper body, so a large level (a cycle of many bodies in a pile) costs L log L, not L^2.
  enum class Role : char { Pair, Joint, Covered };
  struct Entry {
    int pair = 0, upper = 0, other = 0, position = 0;
    Role role = Role::Pair;
    int ownBegin = 0, ownEnd = 0;  // Joint: its pairs in `own`
  };
  thread_local std::vector<Entry> entries;
  thread_local std::vector<int> byUpper, own, jointBodies;
  for (std::size_t begin = 0; begin < list.size();) {
    const int level = pairs[list[begin]].level;
    std::size_t end = begin;
    while (end < list.size() && pairs[list[end]].level == level) ++end;
    entries.clear();
    own.clear();
    byUpper.clear();
    for (std::size_t k = begin; k < end; ++k) {
      const ContactPairState& pair = pairs[list[k]];
      if (onlyContacted && !pair.contacted) continue;
      Entry e;
      e.pair = list[k];
      e.upper = levels.levelOf[pair.a] == level ? pair.a : pair.b;
      e.other = e.upper == pair.a ? pair.b : pair.a;
      e.position = static_cast<int>(entries.size());
      if (tasks_.fixedIn(s, e.other) && !tasks_.fixedIn(s, e.upper)) byUpper.push_back(e.position);
      entries.push_back(e);
    }
    // Each upper body's pairs with a partner of infinite mass, in level order.
    std::stable_sort(byUpper.begin(), byUpper.end(),
                     [&](int x, int y) { return entries[x].upper < entries[y].upper; });
    for (std::size_t g = 0; g < byUpper.size();) {
      std::size_t h = g;
      while (h < byUpper.size() && entries[byUpper[h]].upper == entries[byUpper[g]].upper) ++h;
      Entry& first = entries[byUpper[g]];
      const int ownBegin = static_cast<int>(own.size());
      for (std::size_t q = g; q < h; ++q)
        if (!bodies[entries[byUpper[q]].other].kinematic) own.push_back(byUpper[q]);
      if (static_cast<int>(own.size()) - ownBegin > 1 && !bodies[first.other].kinematic) {
        first.role = Role::Joint;
        first.ownBegin = ownBegin;
        first.ownEnd = static_cast<int>(own.size());
        for (int q = ownBegin; q < first.ownEnd; ++q)
          if (own[q] != first.position) entries[own[q]].role = Role::Covered;
      } else {
        own.resize(ownBegin);  // a pair update each
      }
      g = h;
    }
    for (int li = 0; li < settings.shockLevelIterations; ++li) {
      const double eps = double(li + 1) / double(settings.shockLevelIterations);
      for (const Entry& e : entries) {
        if (e.role == Role::Covered) continue;
        SweepTask t;
        t.epsilon = eps;
        t.iterations = settings.shockPairIterations;
        t.shockFriction = true;
        if (e.role == Role::Joint) {
          t.kind = SweepTask::Kind::Joint;
          t.index = e.upper;
          t.listBegin = static_cast<int>(s.lists.size());
          jointBodies.assign(1, e.upper);
          for (int q = e.ownBegin; q < e.ownEnd; ++q) {
            s.lists.push_back(entries[own[q]].pair);
            jointBodies.push_back(entries[own[q]].other);
          }
          t.listEnd = static_cast<int>(s.lists.size());
          addTask(s, mode, step, t, jointBodies.data(), static_cast<int>(jointBodies.size()));
          continue;
        }
        t.kind = SweepTask::Kind::Pair;
        t.index = e.pair;
        const ContactPairState& pair = pairs[e.pair];
        const int touched[2] = {pair.a, pair.b};
        addTask(s, mode, step, t, touched, 2);
      }
    }
    for (std::size_t k = begin; k < end; ++k) {
      const ContactPairState& p = pairs[list[k]];
      for (int body : {p.a, p.b}) {
        if (levels.levelOf[body] != level || tasks_.fixedIn(s, body)) continue;
        SweepTask t;
        t.kind = SweepTask::Kind::Freeze;
        t.index = body;
        addTask(s, mode, step, t, &body, 1);
        tasks_.markFrozen(s, body);
      }
    }
    begin = end;
  }
  const int impulses = runTasks(s, mode, step);
  for (int m : islands.members[island]) bodies[m].frozen = false;
  return impulses;
}

template col::Geometry<2> collisionGeometryOf<2>(const Shape<2>&);
template col::Geometry<3> collisionGeometryOf<3>(const Shape<3>&);
template class ContactWorkspace<2>;
template class ContactWorkspace<3>;

}  // namespace monolith

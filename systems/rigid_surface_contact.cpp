#include "systems/rigid_surface_contact.h"

#include <Eigen/Geometry>

#include "solvers/rigid_rotation.h"

namespace monolith {

namespace dm = solvers::deformable;

namespace {

constexpr int kContactSweeps = 4;

// The bodies with a collider at their current pose (candidateDt = 0) or their candidate pose
// x + dt v, R advanced by exp(dt w); dynamic ones movable when `twoWay`. Into `out` and `owners`,
// reusing their storage.
template <int d>
void rigidFaceBodies(World<d>& world, PreparedShapes<d>& shapes, double candidateDt, bool twoWay,
                     std::vector<dm::RigidFaceBody<d>>& out, std::vector<RigidBody<d>*>& owners) {
  out.clear();
  owners.clear();
  world.template each<RigidBody<d>, Shape<d>, Collider<d>>([&](Entity e, RigidBody<d>& b, Shape<d>& s, Collider<d>& c) {
    dm::RigidFaceBody<d> v;
    v.geometry = &shapes.get(e, s);
    v.friction = c.friction;
    v.R = b.rotation();
    v.x = b.x;
    if (!b.isStatic) {
      v.v = b.v;
      v.omega = b.omega();
      if (candidateDt > 0) {
        v.x += candidateDt * b.v;
        if constexpr (d == 3) v.R = (solvers::rotationExponential(candidateDt * v.omega) * b.orientation).toRotationMatrix();
        else v.R = Eigen::Rotation2Dd(b.orientation + candidateDt * v.omega(0)).toRotationMatrix();
      }
      if (twoWay && !world.template has<KinematicMotion<d>>(e)) {
        v.inverseMass = 1 / b.mass;
        v.inverseInertia = b.worldInverseInertia();
      }
    }
    out.push_back(v);
    owners.push_back(&b);
  });
}

}  // namespace

template <int d>
void RigidSurfaceContact<d>::run(World<d>& world, StepContext& ctx) {
  const bool candidate = stage_ == Stage::Collisions || stage_ == Stage::Contact;
  const bool twoWay = stage_ == Stage::Collisions || stage_ == Stage::AdvanceVelocity;
  rigidFaceBodies(world, shapes_, candidate ? ctx.dt : 0.0, twoWay, bodies_, owners_);
  if (bodies_.empty()) return;
  const dm::CollisionSurface<d>& surface = surfaces_.get(world);
  particles_.gather(world);
  at_ = particles_.x;
  if (candidate)
    for (std::size_t i = 0; i < at_.size(); ++i) at_[i] += ctx.dt * particles_.v[i];
  dm::FaceSet<d> faces{&surface.faces, &at_, &particles_.v, &particles_.inverseMass, &surface.thickness, &surface.friction};
  dm::findFaceContacts<d>(bodies_, faces, tree_, work_, contacts_);
  if (stage_ == Stage::AdvancePositions) {
    const double deepest = dm::pushFacesOut<d>(contacts_, surface.faces, particles_.inverseMass, particles_.x);
    ctx.diagnostics.max("rigid_surface_push_out_depth", deepest);
    if (deepest > 0) particles_.writePositions();
    return;
  }
  // Step II also sweeps the bodies' centres through the faces over the step: a body fast or small
  // enough to pass a face between the start and the candidate positions is caught there.
  if (stage_ == Stage::Collisions) {
    dm::findSweptFaceContacts<d>(bodies_, faces, particles_.x, ctx.dt, contacts_, sweptTree_, work_, swept_);
    ctx.diagnostics.set("rigid_surface_swept_contacts", static_cast<double>(swept_.size()));
    contacts_.insert(contacts_.end(), swept_.begin(), swept_.end());
  }
  const int impulses = dm::applyFaceContactImpulses<d>(bodies_, faces, contacts_, kContactSweeps);
  ctx.diagnostics.set(name() + "_impulses", impulses);
  if (impulses == 0) return;
  particles_.writeVelocities();
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    if (bodies_[k].inverseMass == 0) continue;
    owners_[k]->v += bodies_[k].impulse / owners_[k]->mass;
    owners_[k]->L += bodies_[k].angularImpulse;
  }
}

template <int d>
std::vector<std::unique_ptr<System<d>>> makeRigidSurfaceContactSystems(const std::vector<Stage>& stages) {
  std::vector<std::unique_ptr<System<d>>> out;
  for (Stage s : stages)
    out.push_back(std::make_unique<RigidSurfaceContact<d>>(s));
  return out;
}

template class RigidSurfaceContact<2>;
template class RigidSurfaceContact<3>;
template std::vector<std::unique_ptr<System<2>>> makeRigidSurfaceContactSystems<2>(const std::vector<Stage>&);
template std::vector<std::unique_ptr<System<3>>> makeRigidSurfaceContactSystems<3>(const std::vector<Stage>&);

}  // namespace monolith

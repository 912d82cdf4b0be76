#pragma once
// Particles of deformable bodies against rigid bodies, both ways (thesis Sec. 4.2: rigid/particle
// pairs are rigid/rigid pairs with the particle a point body of infinite inertia, restitution
// zero and the rigid body's friction; notes 2.3 step 6).
//  * particle_collisions (Step II, Sec. 4.4): before the rigid bodies' own collisions, each
//    particle's candidate position x^n + dt v^{n+1/2} is tested against each body at its candidate
//    pose; an approaching pair closer than the contact thickness gets the impulse (restitution
//    zero, below) on both sides, equal and opposite. It changes v^{n+1/2} of the particle and of
//    the body; the rigid collisions then take the body's v^n as v^{n+1/2} minus its Step I kick,
//    so the change is the body's post-collision velocity as in the thesis. (The thesis's
//    collision loop uses the relative velocity at t^n; v^{n+1/2} is used here: both stages' kicks
//    are the same gravity for bodies in free flight.)
//  * particle_contact (Step III, Sec. 4.5): the particle's candidate position x^n + dt v^{n+1/2}
//    is tested against the body at its candidate pose; a pair closer than the contact thickness
//    and approaching gets the impulse that stops the approach (Coulomb friction: sticking if the
//    sticking impulse lies in the cone, else sliding on the cone's edge). As for rigid bodies
//    (GBF 2003, Sec. 4.5), Step III velocities only steer the position update: the particles'
//    v^{n+1/2} from before Step III are restored after Step IV, and the rigid pipeline restores its
//    own; so here the body is taken as immovable (the particle alone is stopped).
//  * particle_push_out (Step IV, Sec. 4.6.1): a particle inside a body at x^{n+1} is moved to the
//    body's surface along the surface normal; positions only, the body is not moved. Then the
//    saved velocities are restored.
//  * particle_velocity_contact (Step V): the same impulses at x^{n+1} with v^{n+1}, after the
//    velocity update and after the rigid bodies' own velocity contact (Sec. 4.7.2, "friction and
//    contact as a post-process"); here both sides receive the impulse, equal and opposite, so
//    linear momentum passes between particle and body exactly.
// Pairs are visited serially in pool order (bodies, then deformables, then particles) for a
// fixed number of sweeps, so results are the same on any number of threads.
#include <cstdint>
#include <memory>
#include <unordered_map>

#include "components/collider.h"
#include "components/deformable.h"
#include "components/kinematic.h"
#include "components/rigid_body.h"
#include "components/shape.h"
#include "ecs/system.h"
#include "solvers/collision/geometry.h"
#include "solvers/deformable/coupled_damping.h"
#include "systems/deformable_dynamics.h"

namespace monolith {

template <int d>
class PreparedShapes {
 public:
  const solvers::collision::PreparedGeometry<d>& get(Entity e, const Shape<d>& s);

 private:
  std::unordered_map<std::uint64_t, std::unique_ptr<solvers::collision::PreparedGeometry<d>>> shapes_;
};

// The particles' v^{n+1/2} saved before Step III, restored after Step IV (one per body, pool
// order). Lives for one step only, so checkpoints need nothing from it.
struct ParticleContactScratch {
  std::vector<std::vector<double>> savedVelocities;
};

template <int d>
class ParticleRigidContact final : public System<d> {
 public:
  ParticleRigidContact(Stage s, std::shared_ptr<ParticleContactScratch> scratch)
      : stage_(s), scratch_(std::move(scratch)) {}
  std::string name() const override {
    return stage_ == Stage::Collisions ? "particle_collisions"
           : stage_ == Stage::Contact  ? "particle_contact"
                                       : "particle_velocity_contact";
  }
  Stage stage() const override { return stage_; }
  std::vector<std::string> reads() const override {
    return {Shape<d>::kName, Collider<d>::kName, KinematicMotion<d>::kName};
  }
  std::vector<std::string> writes() const override { return {Particles<d>::kName, RigidBody<d>::kName, "diagnostics"}; }
  bool needed(const World<d>& w) const override {
    return w.template count<Particles<d>>() > 0 && w.template count<Collider<d>>() > 0;
  }
  void run(World<d>& world, StepContext& ctx) override;

 private:
  Stage stage_;
  std::shared_ptr<ParticleContactScratch> scratch_;
  PreparedShapes<d> shapes_;
};

template <int d>
class ParticlePushOut final : public System<d> {
 public:
  explicit ParticlePushOut(std::shared_ptr<ParticleContactScratch> scratch) : scratch_(std::move(scratch)) {}
  std::string name() const override { return "particle_push_out"; }
  Stage stage() const override { return Stage::AdvancePositions; }
  std::vector<std::string> reads() const override {
    return {Shape<d>::kName, Collider<d>::kName, RigidBody<d>::kName};
  }
  std::vector<std::string> writes() const override { return {Particles<d>::kName, "diagnostics"}; }
  bool needed(const World<d>& w) const override {
    return w.template count<Particles<d>>() > 0 && w.template count<Collider<d>>() > 0;
  }
  void run(World<d>& world, StepContext& ctx) override;

 private:
  std::shared_ptr<ParticleContactScratch> scratch_;
  PreparedShapes<d> shapes_;
};

// After the step: the deepest particle left inside a rigid body (particles are pushed out in
// Step IV, but a rigid body's own push-out may move it onto them afterwards), as a fraction of
// the smaller of the body's and the particle's deformable body's size, merged into the
// standard max_penetration / max_penetration_ratio columns.
template <int d>
class ParticlePenetration final : public System<d> {
 public:
  std::string name() const override { return "particle_penetration"; }
  Stage stage() const override { return Stage::Diagnostics; }
  std::vector<std::string> reads() const override {
    return {Shape<d>::kName, Collider<d>::kName, RigidBody<d>::kName, Particles<d>::kName};
  }
  std::vector<std::string> writes() const override { return {"diagnostics"}; }
  bool needed(const World<d>& w) const override {
    return w.template count<Particles<d>>() > 0 && w.template count<Collider<d>>() > 0;
  }
  void run(World<d>& world, StepContext& ctx) override;

 private:
  PreparedShapes<d> shapes_;
};

// The damping solves of Steps I and V (Sec. 4.7.1, 4.7.3): the particles of one deformable body
// that touch a rigid body at the candidate positions x + dt v (within twice the contact thickness,
// where resting contacts hover) and do not separate from it, each held along the contact normal:
// its normal velocity relative to the body point's (a dynamic body, then an unknown of the solve)
// or its normal velocity (a static or kinematic body: the point's normal velocity added) set to
// `keep` times the relative approach. Step V keeps half
// (notes 2.6, trapezoid rule: the extrapolated v^{n+1} = 2u - v^{n+1/2} then just stops the
// approach; a particle beyond the thickness from a dynamic body, which the post-process does not
// stop, keeps its own relative normal velocity); Step I, a backward Euler step to v^{n+1/2},
// keeps none. The damping forces then
// see the particles moving with the body; contact itself follows as the post-process. The thesis
// holds contacts in Step V only; without Step I's (measured on density_ratio_heavy_box at dt =
// 1e-4, beta = 0.01) the damping of the light top particles, free in the solve, lets the energy
// rise 6 %.
//
// `rigidRows`: the rigid unknowns' own constraints in the same solves (Sec. 4.7.1, 4.7.3): their
// contacts with other rigid bodies at the candidate poses (narrow-phase points within twice the
// thickness or 1 % of the body's size), temporary normal-only joints on the relative normal
// velocity at the point with the same `keep` rule as the particles' (a separating point held at
// its own relative normal velocity, so that the rest of a manifold is no pivot), and the
// velocity rows of their joints (target zero: the joint stages post-stabilize to it). A dynamic
// body touching or jointed to an unknown becomes an unknown too (appended to `unknowns`, in the
// order found), so that a box resting on a box on a deformable slab is one consistent solve.
template <int d>
struct RigidConstraintRow {
  Entity a, b;  // b invalid: the other side is static, kinematic or the world (its velocity in target)
  solvers::deformable::DampingTwist<d> ga, gb;
  double target = 0;
};

template <int d>
class DampingSolveContacts {
 public:
  std::vector<NormalConstraint<d>> of(World<d>& world, const Particles<d>& p, double dt, double keep);
  std::vector<RigidConstraintRow<d>> rigidRows(World<d>& world, std::vector<Entity>& unknowns, double dt, double keep);

 private:
  PreparedShapes<d> shapes_;
};

// Step III, IV and V systems above sharing one scratch (the registry's "particle_contact").
template <int d>
std::vector<std::unique_ptr<System<d>>> makeParticleContactSystems();
// Step II (the registry's "particle_collisions", registered before the rigid collisions).
template <int d>
std::vector<std::unique_ptr<System<d>>> makeParticleCollisionSystems();

}  // namespace monolith

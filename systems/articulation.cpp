#include "systems/articulation.h"

#include <algorithm>
#include <stdexcept>
#include <unordered_map>

#include "components/collider.h"
#include "components/kinematic.h"
#include "components/sleep.h"
#include "solvers/articulation/joint_constraints.h"
#include "solvers/rigid_rotation.h"
#include "systems/joint_assembly.h"
#include "systems/rigid_inertia.h"

namespace monolith {


ArticulationSolver articulationSettings(const World<3>& world) {
  const auto* pool = world.findPool<ArticulationSolver>();
  return pool && pool->size() > 0 ? pool->components()[0] : ArticulationSolver{};
}

std::vector<std::string> JointSystem::reads() const {
  return {Joint::kName, ArticulationSolver::kName, KinematicMotion<3>::kName, Sleep<3>::kName};
}
std::vector<std::string> JointSystem::writes() const { return {RigidBody<3>::kName}; }

namespace {

// PD drive of the revolute joints with a target (Step III.2): an angular impulse about the
// hinge, dt (kp (a* - a) + kd (a*' - a')), on the child and its opposite on the parent.
void applyPd(JointAssembly& a, double t, double dt) {
  constexpr double kPi = 3.14159265358979323846;
  for (std::size_t k = 0; k < a.joints.size(); ++k) {
    const Joint& joint = *a.components[k];
    if (joint.pd == PdTarget::None) continue;
    const auto& def = a.joints[k];
    auto& P = a.bodies[def.parent];
    auto& C = a.bodies[def.child];
    const Eigen::Vector3d axis = solvers::jointAxis(def, P.q);
    const double angle = solvers::revoluteAngle(def, P.q, C.q);
    const double rate = axis.dot(C.w - P.w);
    double target = 0, targetRate = 0;
    joint.targetAt(t, target, targetRate);
    double error = target - angle;
    if (error > kPi) error -= 2 * kPi;
    if (error < -kPi) error += 2 * kPi;
    const Eigen::Vector3d impulse = dt * (joint.kp * error + joint.kd * (targetRate - rate)) * axis;
    if (C.invMass > 0) C.angularImpulse += impulse, C.w += C.invInertia * impulse;
    if (P.invMass > 0) P.angularImpulse -= impulse, P.w -= P.invInertia * impulse;
  }
}

bool anyPd(const World<3>& w) {
  const auto* pool = w.findPool<Joint>();
  if (!pool) return false;
  for (const Joint& j : pool->components())
    if (j.pd != PdTarget::None) return true;
  return false;
}

// Post-stabilization proper: the mass-weighted projection of the velocities onto the joints.
void project(JointAssembly& a, const ArticulationSolver& s, StepContext& ctx) {
  const auto rows = a.rows();
  const std::vector<solvers::Vector6d> zero(rows.size(), solvers::Vector6d::Zero());
  const solvers::ProjectionReport r =
      s.post == ArticulationSolver::Method::Global
          ? solvers::projectGlobal(rows, zero, a.bodies, s.postIterations * static_cast<int>(std::max<std::size_t>(rows.size(), 1)),
                                   s.postTolerance)
          : solvers::projectPairwise(rows, zero, a.bodies, s.postIterations, s.postTolerance);
  a.writeBack();
  ctx.diagnostics.max("joint_post_iterations", r.iterations);
}

}  // namespace

void postStabilizeJointVelocities(World<3>& world, StepContext& ctx) {
  JointAssembly a(world);
  project(a, articulationSettings(world), ctx);
}

std::string PostStabilizeJoints::name() const {
  switch (place_) {
    case Place::AfterCollisions: return "post_stabilize_collisions";
    case Place::AfterPositions: return "post_stabilize_positions";
    case Place::AfterVelocities: return "post_stabilize_velocities";
  }
  return "?";
}

Stage PostStabilizeJoints::stage() const {
  switch (place_) {
    case Place::AfterCollisions: return Stage::Collisions;
    case Place::AfterPositions: return Stage::AdvancePositions;
    case Place::AfterVelocities: return Stage::AdvanceVelocity;
  }
  return Stage::Count;
}

void PostStabilizeJoints::run(World<3>& world, StepContext& ctx) {
  const ArticulationSolver s = articulationSettings(world);
  if (place_ == Place::AfterPositions && !memory_->entity.empty()) {
    for (std::size_t i = 0; i < memory_->entity.size(); ++i) {
      RigidBody<3>* b = world.get<RigidBody<3>>(memory_->entity[i]);
      b->v = memory_->v[i];
      b->L = memory_->L[i];
    }
  }
  JointAssembly a(world);
  if (place_ == Place::AfterVelocities) applyPd(a, ctx.time + 0.5 * ctx.dt, ctx.dt);
  project(a, s, ctx);
  if (place_ == Place::AfterCollisions) {
    memory_->entity.clear(), memory_->v.clear(), memory_->L.clear();
    for (std::size_t i = 1; i < a.bodies.size(); ++i) {
      if (a.bodies[i].invMass == 0) continue;
      memory_->entity.push_back(a.entity[i]);
      memory_->v.push_back(a.rigid[i]->v);
      memory_->L.push_back(a.rigid[i]->L);
    }
  }
}

bool JointPdControl::needed(const World<3>& w) const { return anyPd(w); }

void JointPdControl::run(World<3>& world, StepContext& ctx) {
  JointAssembly a(world);
  applyPd(a, ctx.time + 0.5 * ctx.dt, ctx.dt);
  a.writeBack();
}

std::vector<std::unique_ptr<System<3>>> makeJointSystems() {
  auto memory = std::make_shared<JointVelocityMemory>();
  using Place = PostStabilizeJoints::Place;
  std::vector<std::unique_ptr<System<3>>> v;
  v.push_back(std::make_unique<PostStabilizeJoints>(Place::AfterCollisions, memory));
  v.push_back(std::make_unique<PreStabilizeJoints>());
  v.push_back(std::make_unique<PostStabilizeJoints>(Place::AfterPositions, memory));
  v.push_back(std::make_unique<PostStabilizeJoints>(Place::AfterVelocities, memory));
  v.push_back(std::make_unique<JointDiagnostics>());
  return v;
}

bool PreStabilizeJoints::needed(const World<3>& w) const {
  return JointSystem::needed(w) && articulationSettings(w).preStabilization;
}

void PreStabilizeJoints::run(World<3>& world, StepContext& ctx) {
  // With colliders and contact rounds, contact ran pre-stabilization between its sweeps.
  if (world.count<Collider<3>>() > 0 && articulationSettings(world).contactRounds > 0) return;
  preStabilizeJointVelocities(world, ctx);
}

int jointContactRounds(const World<3>& world) {
  return world.count<Joint>() > 0 && articulationSettings(world).preStabilization ? articulationSettings(world).contactRounds
                                                                                     : 0;
}

void preStabilizeJointVelocities(World<3>& world, StepContext& ctx) {
  const ArticulationSolver s = articulationSettings(world);
  JointAssembly a(world);
  const double dt = ctx.dt;
  const RigidRotationSettings rule = world.settings().rigidRotation;
  std::vector<solvers::BodyInertia> inertia(a.bodies.size());
  for (std::size_t i = 1; i < a.bodies.size(); ++i)
    if (a.bodies[i].invMass > 0) inertia[i] = bodyInertia(*a.rigid[i]);
  // Exactly what Step IV will do with these velocities (advance_positions.cpp,
  // kinematic_motion.cpp), so that the joints close on the poses the step ends at.
  const solvers::PosePredictor predict = [&](int i, const solvers::ConstraintBody& b, Eigen::Vector3d& x,
                                             Eigen::Quaterniond& q) {
    x = b.x;
    q = b.q;
    if (i == 0 || (a.rigid[i]->isStatic)) return;
    x = b.x + dt * b.v;
    if (a.kinematic[i]) {
      const double angle = dt * b.w.norm();
      if (angle > 0) q = (Eigen::Quaterniond(Eigen::AngleAxisd(angle, b.w.normalized())) * b.q).normalized();
      return;
    }
    if (b.invMass == 0) {  // asleep: held still
      x = b.x;
      return;
    }
    const Eigen::Vector3d L = a.rigid[i]->L + b.angularImpulse;
    const double energyBefore = solvers::rotationalKineticEnergy(inertia[i], b.q, L);
    q = solvers::advanceOrientation(static_cast<solvers::RotationOrder>(rule.order), dt, inertia[i], b.q, L);
    if (rule.energyFix) solvers::correctOrientationForKineticEnergy(q, inertia[i], L, energyBefore);
  };
  const solvers::PreStabilizationReport r =
      solvers::preStabilize(a.joints, a.bodies, predict, dt, s.pre == ArticulationSolver::Method::Global,
                            s.preIterations, s.preTolerance);
  a.writeBack();
  ctx.diagnostics.max("joint_pre_iterations", r.iterations);
  ctx.diagnostics.max("joint_pre_error_left", r.errorAfter);
}

void JointDiagnostics::run(World<3>& world, StepContext& ctx) {
  JointAssembly a(world);
  double position = 0, angle = 0, velocity = 0;
  for (const auto& def : a.joints) {
    const auto& P = a.bodies[def.parent];
    const auto& C = a.bodies[def.child];
    const solvers::JointError e = solvers::jointError(def, P.x, P.q, C.x, C.q);
    position = std::max(position, e.linear.norm());
    angle = std::max(angle, e.angular.norm());
    const solvers::JointRows rows = solvers::jointRows(def, a.bodies);
    velocity = std::max(velocity, solvers::largestEntry(solvers::rowVelocities(rows, a.bodies), rows.rows()));
  }
  ctx.diagnostics.set("joint_error_max", position);
  ctx.diagnostics.set("joint_angle_error_max", angle);
  ctx.diagnostics.set("joint_velocity_error_max", velocity);
}

}  // namespace monolith

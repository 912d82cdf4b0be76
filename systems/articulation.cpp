#include "systems/articulation.h"

#include <algorithm>
#include <stdexcept>
#include <unordered_map>

#include "components/collider.h"
#include "components/kinematic.h"
#include "components/sleep.h"
#include "solvers/articulation/joint_constraints.h"
#include "solvers/rigid_rotation.h"
#include "solvers/rigid_rotation_settings.h"
#include "systems/joint_assembly.h"
#include "systems/rigid_inertia.h"

namespace monolith {


template <int d>
ArticulationSolver articulationSettings(const World<d>& world) {
  const auto* pool = world.template findPool<ArticulationSolver>();
  return pool && pool->size() > 0 ? pool->components()[0] : ArticulationSolver{};
}

template <int d>
std::vector<std::string> JointSystem<d>::reads() const {
  return {ArticulationJoint<d>::kName, ArticulationSolver::kName, KinematicMotion<d>::kName, Sleep<d>::kName};
}
template <int d>
std::vector<std::string> JointSystem<d>::writes() const {
  return {RigidBody<d>::kName};
}

namespace {

// PD drive of the revolute joints with a target (Step III.2): an angular impulse about the
// hinge, dt (kp (a* - a) + kd (a*' - a')), on the child and its opposite on the parent.
template <int d>
void applyPd(JointAssembly<d>& a, double t, double dt) {
  constexpr double kPi = 3.14159265358979323846;
  for (std::size_t k = 0; k < a.joints.size(); ++k) {
    const ArticulationJoint<d>& joint = *a.components[k];
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

template <int d>
bool anyPd(const World<d>& w) {
  const auto* pool = w.template findPool<ArticulationJoint<d>>();
  if (!pool) return false;
  for (const ArticulationJoint<d>& j : pool->components())
    if (j.pd != PdTarget::None) return true;
  return false;
}

// Post-stabilization proper: the mass-weighted projection of the velocities onto the joints.
template <int d>
void project(JointAssembly<d>& a, const ArticulationSolver& s, StepContext& ctx) {
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

template <int d>
void postStabilizeJointVelocities(World<d>& world, StepContext& ctx) {
  JointAssembly<d> a(world);
  project(a, articulationSettings(world), ctx);
}

template <int d>
std::string PostStabilizeJoints<d>::name() const {
  switch (place_) {
    case Place::AfterCollisions: return "post_stabilize_collisions";
    case Place::AfterPositions: return "post_stabilize_positions";
    case Place::AfterVelocities: return "post_stabilize_velocities";
  }
  return "?";
}

template <int d>
Stage PostStabilizeJoints<d>::stage() const {
  switch (place_) {
    case Place::AfterCollisions: return Stage::Collisions;
    case Place::AfterPositions: return Stage::AdvancePositions;
    case Place::AfterVelocities: return Stage::AdvanceVelocity;
  }
  return Stage::Count;
}

template <int d>
void PostStabilizeJoints<d>::run(World<d>& world, StepContext& ctx) {
  const ArticulationSolver s = articulationSettings(world);
  if (place_ == Place::AfterPositions && !memory_->entity.empty()) {
    for (std::size_t i = 0; i < memory_->entity.size(); ++i) {
      RigidBody<d>* b = world.template get<RigidBody<d>>(memory_->entity[i]);
      b->v = memory_->v[i];
      b->L = memory_->L[i];
    }
  }
  JointAssembly<d> a(world);
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

template <int d>
bool JointPdControl<d>::needed(const World<d>& w) const {
  return anyPd(w);
}

template <int d>
void JointPdControl<d>::run(World<d>& world, StepContext& ctx) {
  JointAssembly<d> a(world);
  applyPd(a, ctx.time + 0.5 * ctx.dt, ctx.dt);
  a.writeBack();
}

template <int d>
std::vector<std::unique_ptr<System<d>>> makeJointSystems() {
  auto memory = std::make_shared<JointVelocityMemory<d>>();
  using Place = typename PostStabilizeJoints<d>::Place;
  std::vector<std::unique_ptr<System<d>>> v;
  v.push_back(std::make_unique<PostStabilizeJoints<d>>(Place::AfterCollisions, memory));
  v.push_back(std::make_unique<PreStabilizeJoints<d>>());
  v.push_back(std::make_unique<PostStabilizeJoints<d>>(Place::AfterPositions, memory));
  v.push_back(std::make_unique<PostStabilizeJoints<d>>(Place::AfterVelocities, memory));
  v.push_back(std::make_unique<JointDiagnostics<d>>());
  return v;
}

template <int d>
bool PreStabilizeJoints<d>::needed(const World<d>& w) const {
  return JointSystem<d>::needed(w) && articulationSettings(w).preStabilization;
}

template <int d>
void PreStabilizeJoints<d>::run(World<d>& world, StepContext& ctx) {
  // With colliders and contact rounds, contact ran pre-stabilization between its sweeps.
  if (jointContactRounds(world) > 0 && world.template count<Collider<d>>() > 0) return;
  preStabilizeJointVelocities(world, ctx);
}

template <int d>
int jointContactRounds(const World<d>& world) {
  return world.template count<ArticulationJoint<d>>() > 0 && articulationSettings(world).preStabilization
             ? articulationSettings(world).contactRounds
             : 0;
}

template <int d>
void preStabilizeJointVelocities(World<d>& world, StepContext& ctx) {
  const ArticulationSolver s = articulationSettings(world);
  JointAssembly<d> a(world);
  const double dt = ctx.dt;
  const RigidRotationSettings rule = world.template resource<RigidRotationSettings>();
  std::vector<solvers::BodyInertia> inertia(a.bodies.size());
  if constexpr (d == 3)
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
    if constexpr (d == 2) {  // the angle advances by dt w (advance_positions.cpp)
      const double angle = a.rigid[i]->orientation + dt * b.w.z();
      q = Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()));
    } else {
      const Eigen::Vector3d L = a.rigid[i]->L + b.angularImpulse;
      const double energyBefore = solvers::rotationalKineticEnergy(inertia[i], b.q, L);
      q = solvers::advanceOrientation(static_cast<solvers::RotationOrder>(rule.order), dt, inertia[i], b.q, L);
      if (rule.energyFix) solvers::correctOrientationForKineticEnergy(q, inertia[i], L, energyBefore);
    }
  };
  const solvers::PreStabilizationReport r =
      solvers::preStabilize(a.joints, a.bodies, predict, dt, s.pre == ArticulationSolver::Method::Global,
                            s.preIterations, s.preTolerance);
  a.writeBack();
  ctx.diagnostics.max("joint_pre_iterations", r.iterations);
  ctx.diagnostics.max("joint_pre_error_left", r.errorAfter);
}

template <int d>
void JointDiagnostics<d>::run(World<d>& world, StepContext& ctx) {
  JointAssembly<d> a(world);
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

#define MONOLITH_JOINT_STAGES(d)                                                          \
  template class JointSystem<d>;                                                         \
  template class PostStabilizeJoints<d>;                                                 \
  template class JointPdControl<d>;                                                      \
  template class PreStabilizeJoints<d>;                                                  \
  template class JointDiagnostics<d>;                                                    \
  template ArticulationSolver articulationSettings<d>(const World<d>&);                  \
  template void preStabilizeJointVelocities<d>(World<d>&, StepContext&);                 \
  template void postStabilizeJointVelocities<d>(World<d>&, StepContext&);                \
  template int jointContactRounds<d>(const World<d>&);                                   \
  template std::vector<std::unique_ptr<System<d>>> makeJointSystems<d>();
MONOLITH_JOINT_STAGES(2)
MONOLITH_JOINT_STAGES(3)
#undef MONOLITH_JOINT_STAGES

}  // namespace monolith

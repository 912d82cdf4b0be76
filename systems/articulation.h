#pragma once
// Articulated rigid bodies (thesis Sec. 4.4-4.7, App. C): the joint stages of the Newmark step.
//   post_stabilize_collisions  Step II.2   project the velocities after collisions onto the joints
//   joint_pd_control           Step III.2  PD drive of revolute joints, as impulses
//   pre_stabilize_joints       Step III.3  impulses so that Step IV's positions satisfy the joints
//   post_stabilize_positions   Step IV.3   project the velocities at the new positions
//   post_stabilize_velocities  Step V.4    project the final velocities
//   joint_diagnostics          joint_error_max, joint_angle_error_max, joint_velocity_error_max
// A scene without joints schedules none of them. The numerics are in solvers/articulation; the
// stages, and their coupling with contact below, are the same in 2-D (the joints and contact
// points of the plane z = 0, systems/joint_assembly.h).
#include "components/joint.h"
#include "components/rigid_body.h"
#include "ecs/system.h"

#include <cstdint>
#include <memory>

namespace monolith {

template <int d>
class JointSystem : public System<d> {
 public:
  std::vector<std::string> reads() const override;
  std::vector<std::string> writes() const override;
  bool needed(const World<d>& w) const override { return w.template count<ArticulationJoint<d>>() > 0; }
};

// The jointed bodies' velocities after Step II (v-hat^{n+1/2} = v-hat^n + dt/2 F^n/m), kept
// within one step: pre-stabilization's and PD's impulses of Step III only serve the positions
// (Sec. 4.6: Step IV.3 post-stabilizes v-hat^n), so Step IV restores these before projecting.
template <int d>
struct JointVelocityMemory {
  std::vector<Entity> entity;
  std::vector<Eigen::Matrix<double, d, 1>> v;
  std::vector<AngularVec<d>> L;
};

// Post-stabilization at one of its three places. After collisions it also remembers the
// velocities; after the positions it first restores them; after the velocities it first applies
// the PD drives again (Sec. 4.7 step 4: post-stabilization, PD, contact, post-stabilization).
template <int d>
class PostStabilizeJoints final : public JointSystem<d> {
 public:
  enum class Place { AfterCollisions, AfterPositions, AfterVelocities };
  PostStabilizeJoints(Place place, std::shared_ptr<JointVelocityMemory<d>> memory)
      : place_(place), memory_(std::move(memory)) {}
  std::string name() const override;
  Stage stage() const override;
  void run(World<d>& world, StepContext& ctx) override;

 private:
  Place place_;
  std::shared_ptr<JointVelocityMemory<d>> memory_;
};

template <int d>
class JointPdControl final : public JointSystem<d> {
 public:
  std::string name() const override { return "joint_pd_control"; }
  Stage stage() const override { return Stage::Contact; }
  bool needed(const World<d>& w) const override;
  void run(World<d>& world, StepContext& ctx) override;
};

template <int d>
class PreStabilizeJoints final : public JointSystem<d> {
 public:
  std::string name() const override { return "pre_stabilize_joints"; }
  Stage stage() const override { return Stage::Contact; }
  bool needed(const World<d>& w) const override;
  void run(World<d>& world, StepContext& ctx) override;
};

template <int d>
class JointDiagnostics final : public JointSystem<d> {
 public:
  std::string name() const override { return "joint_diagnostics"; }
  Stage stage() const override { return Stage::Diagnostics; }
  std::vector<std::string> writes() const override { return {}; }
  void run(World<d>& world, StepContext& ctx) override;
};

// Pre-stabilization on the bodies' velocities (what pre_stabilize_joints runs), and how many
// rounds of it Step III's contact interleaves with its sweeps (0 without joints or with
// pre-stabilization off). Step III.3 of Sec. 4.5 processes contact and
// pre-stabilization together; with rounds, pre_stabilize_joints itself does nothing in a scene
// with colliders.
template <int d>
void preStabilizeJointVelocities(World<d>& world, StepContext& ctx);
template <int d>
int jointContactRounds(const World<d>& world);
// Post-stabilization (the projection onto the joints) of the bodies' velocities; Step V's
// contact interleaves it with its sweeps for the same rounds (Sec. 4.7.1: contacts and joints in
// one constrained solve, here by alternating the two projections).
template <int d>
void postStabilizeJointVelocities(World<d>& world, StepContext& ctx);

// Step IV, at the end of interpenetration resolution, before it writes its poses (called from
// systems/interpenetration.cpp; systems/joint_contacts.cpp). The jointed bodies that can move
// start again from where Step IV's advance put them (the bodies' poses still) and are displaced,
// by the least mass-weighted displacement, so that their joints close and their contacts -- with
// the other bodies where push-out left them -- separate (solvers/articulation/joint_closing.h).
// Their poses in `ws` are replaced. Push-out, one contact at a time, pulled joints apart by
// centimetres in a pile from overlaps under a millimetre, and closing the joints afterwards
// pushed the bodies back into their contacts, every step. Diagnostics joint_push_out_error (the
// joint error at push-out's poses), joint_push_out_contacts, joint_push_out_error_left.
template <int d>
class ContactWorkspace;
template <int d>
void resolveJointedInterpenetration(World<d>& world, ContactWorkspace<d>& ws, StepContext& ctx);

// Step V, in velocity_contact before its sweeps (systems/joint_contacts.cpp; Sec. 4.7.1/4.7.3:
// contacts as temporary joints in the constrained solve): the jointed bodies' velocities
// projected onto their joints and their contacts together (normal rows, friction in the cone;
// solvers::projectWithContacts), the other bodies held still with their own velocities. Before
// the sweeps, since after them the contacts carry no normal impulse for friction to lean on.
template <int d>
void postStabilizeWithContacts(World<d>& world, const ContactWorkspace<d>& ws, StepContext& ctx);

// Step III, after shock propagation, with `step_three_contact_solve` (called from
// systems/contact.cpp): the jointed bodies' velocities as Step III's contact started
// (ContactWorkspace::stepThreeStartV) projected onto their joints and contacts as in Step V, at
// the time-n poses, the points as far apart as the bodies reach in the step; so that Step IV
// advances with velocities that keep the joints closed and the contacts sticking, instead of
// those contact's last sweeps and shock propagation left (which open the joints; the jointed
// position solve then closed them by displacements no friction held: a creep at rest).
template <int d>
void preStabilizeWithContacts(World<d>& world, const ContactWorkspace<d>& ws, StepContext& ctx);

// All the joint systems, sharing one velocity memory.
template <int d>
std::vector<std::unique_ptr<System<d>>> makeJointSystems();

// The scene's solver settings (its "articulation" component, else the defaults).
template <int d>
ArticulationSolver articulationSettings(const World<d>& world);

}  // namespace monolith

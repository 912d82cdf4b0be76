#pragma once
// ArticulationJoint<d> (Joint in 3-D, Joint2 in 2-D): one articulation joint between a parent
// and a child rigid body, in maximal coordinates (thesis Sec. 4.4-4.7, App. C; Weinstein, Teran
// and Fedkiw 2006). The parent may be "world". Each body carries a joint frame (a point and an
// orientation -- a quaternion in 3-D, an angle in 2-D -- in the body's frame); the joint type
// says which relative motions of the child's frame against the parent's are allowed:
//   fixed      none
//   revolute   rotation about the frames' z axis (a hinge); optional PD drive of the angle
//   spherical  any rotation about the common point
//   prismatic  translation along the parent frame's z axis
//   universal  rotation about the parent frame's x axis and the child frame's y axis
//   twist      rotation about and translation along the parent frame's z axis (the twist joint
//              of Fig. 4.5; PhysBAM's prismatic twist joint, here with a free slide)
// In 2-D (three DOFs a body) only fixed, revolute (a pin: rotation in the plane) and prismatic
// (translation along the parent frame's x axis) exist; the solvers see a 2-D joint as the 3-D
// joint of the plane with its out-of-plane rows dropped (systems/joint_assembly.h).
// Bodies are named, not held as entity handles: the names survive checkpoints as they are.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <vector>

#include "components/rigid_body.h"

namespace monolith {

enum class JointType : int { Fixed = 0, Revolute, Spherical, Prismatic, Universal, Twist };

inline const char* jointTypeName(JointType t) {
  switch (t) {
    case JointType::Fixed: return "fixed";
    case JointType::Revolute: return "revolute";
    case JointType::Spherical: return "spherical";
    case JointType::Prismatic: return "prismatic";
    case JointType::Universal: return "universal";
    case JointType::Twist: return "twist";
  }
  return "?";
}

// Target of a revolute joint's PD drive (Step III.2): constant, a sinusoid
// offset + amplitude sin(2 pi frequency t + phase), or keyframes (t_k, angle_k) joined linearly
// and held outside their span.
enum class PdTarget : int { None = 0, Constant, Sinusoid, Keyframes };

template <int d>
struct ArticulationJoint {
  static constexpr const char* kName = "joint";
  using VecD = Eigen::Matrix<double, d, 1>;

  JointType type = JointType::Spherical;
  std::string parent = "world";  // entity name, or "world"
  std::string child;             // entity name
  VecD parentAnchor = VecD::Zero();  // in the parent's body frame (world frame for "world")
  VecD childAnchor = VecD::Zero();   // in the child's body frame
  Orientation<d> parentFrame = RigidBody<d>::identityOrientation();  // joint frame orientation on the parent
  Orientation<d> childFrame = RigidBody<d>::identityOrientation();   // ... on the child

  // Angle limits of a revolute or twist joint (rad, lower < upper): a one-sided row about the
  // hinge, active while the joint is at or past a limit and moving (or predicted) further out.
  bool limited = false;
  double lower = 0, upper = 0;
  // Slide limits of a prismatic or twist joint (m, lower < upper; the child's anchor along the
  // parent frame's axis from the parent's anchor): a linear row along the axis, active likewise.
  bool slideLimited = false;
  double slideLower = 0, slideUpper = 0;

  // PD drive of a revolute joint's angle (impulse per step dt (kp (a* - a) + kd (a*' - a'))).
  PdTarget pd = PdTarget::None;
  double kp = 0, kd = 0;
  double target = 0;  // Constant: the angle; Sinusoid: the offset
  double amplitude = 0, frequency = 0, phase = 0;
  std::vector<double> keyTimes, keyAngles;

  // Scene input given in the world frame at the initial poses ("anchor", "axis"), turned into
  // the body-frame fields above when the scene is loaded; not state. The axis is the frames' z
  // in 3-D, their x (a prismatic joint's slide) in 2-D.
  bool anchorInWorld = false, axisInWorld = false;
  VecD worldAnchor = VecD::Zero(), worldAxis = VecD::Unit(d == 3 ? 2 : 0);

  template <class V>
  void visitFields(V& visit) {
    visit("type", type);
    visit("parent", parent);
    visit("child", child);
    visit("parent_anchor", parentAnchor);
    visit("child_anchor", childAnchor);
    visit("parent_frame", parentFrame);
    visit("child_frame", childFrame);
    visit("limited", limited);
    visit("lower", lower);
    visit("upper", upper);
    visit("slide_limited", slideLimited);
    visit("slide_lower", slideLower);
    visit("slide_upper", slideUpper);
    visit("pd", pd);
    visit("kp", kp);
    visit("kd", kd);
    visit("target", target);
    visit("amplitude", amplitude);
    visit("frequency", frequency);
    visit("phase", phase);
    visit("key_times", keyTimes);
    visit("key_angles", keyAngles);
  }

  // Target angle and angular velocity at time t.
  void targetAt(double t, double& angle, double& rate) const;
};

// How the scene's joints are solved: the one "articulation" component of a scene (on any
// entity); without it the defaults below hold.
struct ArticulationSolver {
  static constexpr const char* kName = "articulation";
  enum class Method : int { Pairwise = 0, Global = 1 };
  Method post = Method::Pairwise;  // post-stabilization: Gauss-Seidel over joints, or App. C.1's CG
  Method pre = Method::Pairwise;   // pre-stabilization: Newton per joint, or App. C.2's global Newton + CG
  bool preStabilization = true;
  int postIterations = 50;         // Gauss-Seidel sweeps, or CG iterations x joints for global
  double postTolerance = 1e-10;    // largest joint row velocity left (m/s, rad/s)
  int preIterations = 20;          // Newton sweeps (pairwise) or outer Newton iterations (global)
  double preTolerance = 1e-10;     // largest predicted joint position error left (m, rad)
  // With colliders: rounds of (pre-stabilization, contact sweeps) after Step III's first contact
  // sweeps, so that contact has the last word and the joints close on what it leaves (Sec. 4.5
  // processes contact and pre-stabilization together); 0: pre-stabilization once, after shock
  // propagation.
  int contactRounds = 5;
  // With colliders: sweeps of the jointed bodies' interpenetration resolution, joints and
  // contacts together (systems/articulation.h, resolveJointedInterpenetration); 0: push-out's
  // poses, then the joints closed without regard to contacts.
  int pushOutContactSweeps = 50;
  // With colliders: passes of that solve, each with the contact points found again where the
  // last one left the bodies, while an overlap beyond push-out's tolerance is left.
  int pushOutContactPasses = 1;
  // With colliders: the most sweeps of Step V's joint-and-contact projection (systems/
  // articulation.h, postStabilizeWithContacts); it stops earlier once its rows are within
  // post_tolerance. Projected Gauss-Seidel converges linearly, and what 50 sweeps left of a
  // resting pile's gravity kick stayed in its velocities (docs/benchmarks_articulation.md).
  int contactSolveSweeps = 500;
  // With colliders: rolling resistance (a length, m) at the jointed bodies' contact points in
  // that projection: their relative turn about the contact's tangents is stopped while the
  // angular impulse stays within this x the normal impulse (solvers::ContactRow::rolling).
  // Coulomb friction cannot stop a ball or a capsule rolling without slipping; 0: free rolling.
  double rollingResistance = 0;
  // With colliders: after Step III's shock propagation, the jointed bodies' velocities projected
  // onto their joints and contacts together, as in Step V (systems/articulation.h,
  // preStabilizeWithContacts).
  bool stepThreeContactSolve = false;

  template <class V>
  void visitFields(V& visit) {
    visit("post", post);
    visit("pre", pre);
    visit("pre_stabilization", preStabilization);
    visit("post_iterations", postIterations);
    visit("post_tolerance", postTolerance);
    visit("pre_iterations", preIterations);
    visit("pre_tolerance", preTolerance);
    visit("contact_rounds", contactRounds);
    visit("push_out_contact_sweeps", pushOutContactSweeps);
    visit("push_out_contact_passes", pushOutContactPasses);
    visit("contact_solve_sweeps", contactSolveSweeps);
    visit("rolling_resistance", rollingResistance);
    visit("step_three_contact_solve", stepThreeContactSolve);
  }
};

using Joint = ArticulationJoint<3>;
using Joint2 = ArticulationJoint<2>;

template <int d>
inline void ArticulationJoint<d>::targetAt(double t, double& angle, double& rate) const {
  angle = 0;
  rate = 0;
  switch (pd) {
    case PdTarget::None: return;
    case PdTarget::Constant: angle = target; return;
    case PdTarget::Sinusoid: {
      const double w = 2 * 3.14159265358979323846 * frequency;
      angle = target + amplitude * std::sin(w * t + phase);
      rate = amplitude * w * std::cos(w * t + phase);
      return;
    }
    case PdTarget::Keyframes: {
      const std::size_t n = keyTimes.size();
      if (n == 0) return;
      if (t <= keyTimes.front()) { angle = keyAngles.front(); return; }
      if (t >= keyTimes.back()) { angle = keyAngles.back(); return; }
      std::size_t k = 1;
      while (keyTimes[k] < t) ++k;
      const double span = keyTimes[k] - keyTimes[k - 1];
      rate = (keyAngles[k] - keyAngles[k - 1]) / span;
      angle = keyAngles[k - 1] + rate * (t - keyTimes[k - 1]);
      return;
    }
  }
}

}  // namespace monolith
